//! What a sweep varies: `--param NAME=SPEC` values, the runs they make (a Cartesian
//! product, or a Latin hypercube with `--samples`), and the slice of them one shard runs.
//!
//! SPEC is one of
//! - `a:b:n`: n values evenly spaced from a to b, both included (`5:50:10`);
//! - `a:b:n:log`: n values evenly spaced in log scale (a, b > 0);
//! - `a,b,c`: the values listed;
//! - `a`: one value;
//! - `a:b` (with `--samples` only): the interval a Latin hypercube samples.

use std::fmt;

/// The most runs one sweep may define (a typo such as `0:1:1e9` is refused before it
/// starts).
pub const MAX_RUNS: u64 = 100_000_000;

/// The values of one swept parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    /// Listed values (a range expands to its list).
    List(Vec<f64>),
    /// An interval sampled by the Latin hypercube (`--samples`).
    Interval(f64, f64),
}

/// One `--param NAME=SPEC`.
#[derive(Debug, Clone, PartialEq)]
pub struct Swept {
    /// The parameter's name.
    pub name: String,
    /// SPEC as written, without whitespace (recorded in the CSV's `parameters` line, whose
    /// specs `merge` reads back split at whitespace).
    pub spec: String,
    /// Its values.
    pub values: Values,
    /// Its unit as the model declares it (`N/m`; empty when it declares none or the model
    /// is not known, as for `merge` of a model file), for the figures' axes.
    pub unit: String,
}

impl Swept {
    /// Every value this parameter takes in the sweep, for the bounds check (for an
    /// interval, its two ends).
    pub fn extremes(&self) -> Vec<f64> {
        match &self.values {
            Values::List(v) => v.clone(),
            Values::Interval(a, b) => vec![*a, *b],
        }
    }
}

/// Parses `NAME=SPEC`; the error says what is wrong with it.
pub fn parse_param(text: &str) -> Result<Swept, String> {
    let Some((name, spec)) = text.split_once('=') else {
        return Err(format!(
            "`{text}` is not NAME=VALUES (e.g. k=20,40,80 or omega=5:50:10)"
        ));
    };
    let (name, spec) = (name.trim(), spec.trim());
    if name.is_empty() {
        return Err(format!(
            "`{text}`: the parameter's name is missing before `=`"
        ));
    }
    let values = parse_values(spec).map_err(|e| format!("{name}={spec}: {e}"))?;
    Ok(Swept {
        name: name.to_string(),
        spec: spec.split_whitespace().collect(),
        values,
        unit: String::new(),
    })
}

fn number(text: &str) -> Result<f64, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{}` is not a number", text.trim()))?;
    if value.is_finite() {
        Ok(value)
    } else {
        Err(format!("`{}` is not a finite number", text.trim()))
    }
}

fn count(text: &str) -> Result<usize, String> {
    let text = text.trim();
    let n: f64 = text
        .parse()
        .map_err(|_| format!("the count `{text}` is not a number"))?;
    if n.fract() != 0.0 || !(1.0..=MAX_RUNS as f64).contains(&n) {
        return Err(format!(
            "the count `{text}` must be a whole number from 1 to {MAX_RUNS}"
        ));
    }
    Ok(n as usize)
}

/// SPEC → values.
fn parse_values(spec: &str) -> Result<Values, String> {
    if spec.is_empty() {
        return Err("no values".to_string());
    }
    if spec.contains(',') {
        if spec.contains(':') {
            return Err("a list (a,b,c) and a range (a:b:n) cannot be mixed".to_string());
        }
        let values = spec.split(',').map(number).collect::<Result<Vec<_>, _>>()?;
        return Ok(Values::List(values));
    }
    let parts: Vec<&str> = spec.split(':').collect();
    match parts.as_slice() {
        [one] => Ok(Values::List(vec![number(one)?])),
        [a, b] => {
            let (a, b) = (number(a)?, number(b)?);
            if a == b {
                return Err("the interval a:b is empty (a = b)".to_string());
            }
            Ok(Values::Interval(a.min(b), a.max(b)))
        }
        [a, b, n] => Ok(Values::List(linear(number(a)?, number(b)?, count(n)?))),
        [a, b, n, scale] if scale.trim() == "log" => {
            let (a, b) = (number(a)?, number(b)?);
            if a <= 0.0 || b <= 0.0 {
                return Err("a log range needs a > 0 and b > 0".to_string());
            }
            let exponents = linear(a.ln(), b.ln(), count(n)?);
            let mut values: Vec<f64> = exponents.into_iter().map(f64::exp).collect();
            // The ends exactly as written, not exp(ln(a)).
            if let Some(first) = values.first_mut() {
                *first = a;
            }
            if let (Some(last), true) = (values.last_mut(), count(n)? > 1) {
                *last = b;
            }
            Ok(Values::List(values))
        }
        [_, _, _, other] => Err(format!(
            "`{}` after the count: the only scale is `log` (a:b:n:log)",
            other.trim()
        )),
        _ => Err("too many `:` (a:b:n or a:b:n:log)".to_string()),
    }
}

/// n values from a to b, both ends exact.
fn linear(a: f64, b: f64, n: usize) -> Vec<f64> {
    if n == 1 {
        return vec![a];
    }
    (0..n)
        .map(|k| {
            if k == n - 1 {
                b
            } else {
                a + (b - a) * (k as f64) / ((n - 1) as f64)
            }
        })
        .collect()
}

/// How the runs are made from the swept parameters.
#[derive(Debug, Clone, PartialEq)]
pub enum Design {
    /// Every combination; the first parameter varies slowest.
    Product,
    /// A Latin hypercube of this many runs over the parameters' intervals, drawn with this
    /// seed (the same seed gives the same runs on every machine).
    LatinHypercube {
        /// Number of runs.
        samples: usize,
        /// Seed of the generator.
        seed: u64,
    },
}

/// The runs of a sweep: their parameter values, by run index.
#[derive(Debug, Clone, PartialEq)]
pub struct Runs {
    /// The swept parameters, in the order given.
    pub swept: Vec<Swept>,
    /// How the runs are made.
    pub design: Design,
    /// The Latin hypercube's points, one after the other, each with a value per swept
    /// parameter (empty for a product): one allocation, 8 bytes a value, however many
    /// samples.
    points: Vec<f64>,
}

impl Runs {
    /// The runs of `swept` by `design`; checks that the specs fit the design and that the
    /// number of runs is sensible.
    pub fn new(swept: Vec<Swept>, design: Design) -> Result<Self, String> {
        if swept.is_empty() {
            return Err("nothing to sweep: give at least one --param NAME=VALUES".to_string());
        }
        for (i, s) in swept.iter().enumerate() {
            if swept[..i].iter().any(|t| t.name == s.name) {
                return Err(format!("--param {}: the parameter is given twice", s.name));
            }
        }
        let points = match &design {
            Design::Product => {
                if let Some(s) = swept
                    .iter()
                    .find(|s| matches!(s.values, Values::Interval(..)))
                {
                    return Err(format!(
                        "--param {}={}: an interval a:b needs --samples (a Latin hypercube); \
                         for a grid give a:b:n",
                        s.name, s.spec
                    ));
                }
                let total = swept.iter().try_fold(1u64, |acc, s| {
                    let n = match &s.values {
                        Values::List(v) => v.len() as u64,
                        Values::Interval(..) => 1,
                    };
                    acc.checked_mul(n).filter(|&t| t <= MAX_RUNS)
                });
                if total.is_none() {
                    return Err(format!("the sweep has more than {MAX_RUNS} runs"));
                }
                Vec::new()
            }
            Design::LatinHypercube { samples, seed } => {
                let intervals = swept
                    .iter()
                    .map(|s| match s.values {
                        Values::Interval(a, b) => Ok((a, b)),
                        Values::List(_) => Err(format!(
                            "--param {}={}: with --samples every parameter is an interval \
                             a:b",
                            s.name, s.spec
                        )),
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                if *samples == 0 || *samples as u64 > MAX_RUNS {
                    return Err(format!("--samples must be from 1 to {MAX_RUNS}"));
                }
                latin_hypercube(&intervals, *samples, *seed)
            }
        };
        Ok(Runs {
            swept,
            design,
            points,
        })
    }

    /// Number of runs.
    pub fn len(&self) -> usize {
        match self.design {
            Design::Product => self
                .swept
                .iter()
                .map(|s| match &s.values {
                    Values::List(v) => v.len(),
                    Values::Interval(..) => 1,
                })
                .product(),
            Design::LatinHypercube { samples, .. } => samples,
        }
    }

    /// True when there is no run (never, for runs [`Runs::new`] accepted).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The parameter values of run `index` (in the order of [`Runs::swept`]).
    pub fn values(&self, index: usize) -> Vec<f64> {
        if let Design::LatinHypercube { .. } = self.design {
            let n = self.swept.len();
            return self.points[index * n..(index + 1) * n].to_vec();
        }
        let mut rest = index;
        let mut out = vec![0.0; self.swept.len()];
        for (k, s) in self.swept.iter().enumerate().rev() {
            if let Values::List(v) = &s.values {
                out[k] = v[rest % v.len()];
                rest /= v.len();
            }
        }
        out
    }

    /// The sweep's definition in one line (the CSV's header line and what `merge` compares):
    /// `swing=-0.5:0.5:21 k3=20,40,80` or `… samples 1000 seed 7`.
    pub fn describe(&self) -> String {
        let params: Vec<String> = self
            .swept
            .iter()
            .map(|s| format!("{}={}", s.name, s.spec))
            .collect();
        match self.design {
            Design::Product => params.join(" "),
            Design::LatinHypercube { samples, seed } => {
                format!("{} samples {samples} seed {seed}", params.join(" "))
            }
        }
    }
}

/// `--shard I/N`: the runs whose index is I − 1 modulo N (strided, so that slow and fast
/// regions of the parameter space spread over the shards).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 1-based index.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl Shard {
    /// The whole sweep.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// The runs of this shard among `total`.
    pub fn runs(&self, total: usize) -> impl Iterator<Item = usize> + '_ {
        (self.index - 1..total).step_by(self.count)
    }

    /// Number of runs of this shard among `total`.
    pub fn len(&self, total: usize) -> usize {
        if total < self.index {
            0
        } else {
            (total - self.index) / self.count + 1
        }
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Parses `I/N` (1 ≤ I ≤ N).
pub fn parse_shard(text: &str) -> Result<Shard, String> {
    let Some((i, n)) = text.split_once('/') else {
        return Err(format!(
            "`{text}` is not I/N (e.g. 3/16: the third of 16 shards)"
        ));
    };
    let parse = |s: &str, what: &str| -> Result<usize, String> {
        s.trim()
            .parse::<usize>()
            .map_err(|_| format!("`{text}`: {what} `{}` is not a whole number", s.trim()))
    };
    let (index, count) = (parse(i, "the shard")?, parse(n, "the number of shards")?);
    if count == 0 {
        return Err(format!("`{text}`: the number of shards must be at least 1"));
    }
    if index == 0 || index > count {
        return Err(format!(
            "`{text}`: the shard must be from 1 to {count} (shards are numbered from 1)"
        ));
    }
    Ok(Shard { index, count })
}

/// A small deterministic generator (SplitMix64): the same seed gives the same sweep on
/// every machine and in every shard.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in 0..n.
    fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n.max(1)
    }
}

/// `samples` points in the box `intervals`: each interval cut in `samples` equal strata,
/// each stratum used once per parameter, a uniform point inside it, the strata of the
/// parameters paired by independent random permutations (McKay, Beckman & Conover 1979).
fn latin_hypercube(intervals: &[(f64, f64)], samples: usize, seed: u64) -> Vec<f64> {
    let mut rng = SplitMix(seed);
    let n = intervals.len();
    let mut points = vec![0.0; samples * n];
    for (k, &(a, b)) in intervals.iter().enumerate() {
        let mut strata: Vec<usize> = (0..samples).collect();
        for i in (1..samples).rev() {
            strata.swap(i, rng.below(i + 1));
        }
        for (point, stratum) in points.chunks_exact_mut(n).zip(strata) {
            let u = (stratum as f64 + rng.uniform()) / samples as f64;
            point[k] = a + (b - a) * u;
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    fn values(spec: &str) -> Vec<f64> {
        match parse_param(&format!("k={spec}")).expect("parses").values {
            Values::List(v) => v,
            Values::Interval(a, b) => vec![a, b],
        }
    }

    #[test]
    fn ranges_lists_and_single_values() {
        assert_eq!(values("5:50:10").len(), 10);
        assert_eq!(values("5:50:10")[0], 5.0);
        assert_eq!(values("5:50:10")[9], 50.0);
        assert_eq!(values("0:1:5"), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        assert_eq!(values("20,40,80"), vec![20.0, 40.0, 80.0]);
        assert_eq!(values("3.5"), vec![3.5]);
        assert_eq!(values("7:7:1"), vec![7.0]);
        let log = values("1e-3:1e1:5:log");
        assert_eq!(log.len(), 5);
        assert_eq!((log[0], log[4]), (1e-3, 1e1));
        // Evenly spaced in log: 1e-3, 1e-2, 1e-1, 1, 10 (to round-off of exp and ln).
        assert!((log[2] - 0.1).abs() < 1e-15 && (log[3] - 1.0).abs() < 1e-14);
    }

    #[test]
    fn bad_specs_say_what_is_wrong() {
        for (spec, phrase) in [
            ("k", "not NAME=VALUES"),
            ("=3", "name is missing"),
            ("k=", "no values"),
            ("k=abc", "`abc` is not a number"),
            ("k=1:2:0", "whole number from 1"),
            ("k=1:2:2.5", "whole number from 1"),
            ("k=1:2:3:lin", "the only scale is `log`"),
            ("k=0:2:3:log", "a > 0 and b > 0"),
            ("k=1,2:3", "cannot be mixed"),
            ("k=1:2:3:4:5", "too many"),
            ("k=1,inf", "not a finite number"),
            ("k=2:2", "empty"),
        ] {
            let e = parse_param(spec).expect_err(spec);
            assert!(e.contains(phrase), "{spec}: {e}");
        }
    }

    #[test]
    fn the_product_enumerates_every_combination_first_slowest() {
        let swept = vec![
            parse_param("a=1,2").expect("a"),
            parse_param("b=10,20,30").expect("b"),
        ];
        let runs = Runs::new(swept, Design::Product).expect("valid");
        assert_eq!(runs.len(), 6);
        let all: Vec<Vec<f64>> = (0..6).map(|i| runs.values(i)).collect();
        assert_eq!(all[0], vec![1.0, 10.0]);
        assert_eq!(all[1], vec![1.0, 20.0]);
        assert_eq!(all[3], vec![2.0, 10.0]);
        assert_eq!(all[5], vec![2.0, 30.0]);
        assert_eq!(runs.describe(), "a=1,2 b=10,20,30");
    }

    #[test]
    fn a_latin_hypercube_uses_every_stratum_once_and_repeats_with_its_seed() {
        let swept = vec![
            parse_param("a=0:1").expect("a"),
            parse_param("b=10:20").expect("b"),
        ];
        let design = Design::LatinHypercube {
            samples: 50,
            seed: 7,
        };
        let runs = Runs::new(swept.clone(), design.clone()).expect("valid");
        assert_eq!(runs.len(), 50);
        for (k, (lo, hi)) in [(0.0, 1.0), (10.0, 20.0)].into_iter().enumerate() {
            let mut strata: Vec<usize> = (0..50)
                .map(|i| ((runs.values(i)[k] - lo) / (hi - lo) * 50.0) as usize)
                .collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..50).collect::<Vec<_>>(), "parameter {k}");
        }
        let again = Runs::new(swept.clone(), design).expect("valid");
        assert_eq!(again.values(17), runs.values(17));
        let other = Runs::new(
            swept,
            Design::LatinHypercube {
                samples: 50,
                seed: 8,
            },
        )
        .expect("valid");
        assert_ne!(other.values(17), runs.values(17));
    }

    #[test]
    fn designs_refuse_specs_they_cannot_use() {
        let interval = vec![parse_param("a=0:1").expect("a")];
        assert!(
            Runs::new(interval, Design::Product)
                .unwrap_err()
                .contains("--samples")
        );
        let list = vec![parse_param("a=1,2").expect("a")];
        let lhs = Design::LatinHypercube {
            samples: 4,
            seed: 1,
        };
        assert!(Runs::new(list, lhs).unwrap_err().contains("interval"));
        let twice = vec![
            parse_param("a=1").expect("a"),
            parse_param("a=2").expect("a"),
        ];
        assert!(
            Runs::new(twice, Design::Product)
                .unwrap_err()
                .contains("twice")
        );
        let huge = vec![
            parse_param("a=0:1:100000").expect("a"),
            parse_param("b=0:1:100000").expect("b"),
        ];
        assert!(
            Runs::new(huge, Design::Product)
                .unwrap_err()
                .contains("more than")
        );
        assert!(Runs::new(Vec::new(), Design::Product).is_err());
    }

    #[test]
    fn shards_are_disjoint_and_cover_the_sweep() {
        let total = 103;
        let mut seen = vec![0; total];
        for i in 1..=8 {
            let shard = parse_shard(&format!("{i}/8")).expect("valid");
            let runs: Vec<usize> = shard.runs(total).collect();
            assert_eq!(runs.len(), shard.len(total));
            for r in runs {
                assert_eq!(r % 8, i - 1, "every 8th run from the {i}th");
                seen[r] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        assert_eq!(parse_shard("1/1"), Ok(Shard::ALL));
        for bad in ["0/4", "5/4", "1/0", "a/4", "3", "1/-2"] {
            assert!(parse_shard(bad).is_err(), "{bad}");
        }
        assert_eq!(Shard { index: 5, count: 8 }.len(3), 0);
    }
}
