//! `camchain merge`: the shards of one sweep joined into its whole CSV.
//!
//! Checked before anything is written: every file is a sweep CSV, all of one sweep (same
//! model, parameters, settings and header), with one shard count N and every shard 1…N
//! exactly once. Then the rows are read in run order, one from each shard in turn (shard I
//! holds runs I − 1, I − 1 + N, …, in order), so that a missing, repeated or foreign row is
//! found where it is, named by file and line, and memory stays flat.

use super::spec::{self, Design, Runs};
use super::table::{self, Preamble};
use super::{PlotData, figures};
use crate::CliError;
use crate::args::MergeArgs;
use crate::output;
use std::fs::File;
use std::io::{BufRead, BufReader, Lines, Write};
use std::path::{Path, PathBuf};

/// One shard file being read.
struct Shard {
    path: PathBuf,
    preamble: Preamble,
    header: String,
    lines: Lines<BufReader<File>>,
    /// Lines read so far (for messages).
    line: usize,
}

impl Shard {
    fn open(path: &Path) -> Result<Self, CliError> {
        let failed = |e: String| CliError::Failed(format!("{}: {e}", path.display()));
        let file = File::open(path).map_err(|e| failed(e.to_string()))?;
        let mut lines = BufReader::new(file).lines();
        let mut head = Vec::new();
        for _ in 0..5 {
            match lines.next() {
                Some(Ok(line)) => head.push(line),
                Some(Err(e)) => return Err(failed(e.to_string())),
                None => return Err(failed("too short for a sweep CSV".to_string())),
            }
        }
        let refs: Vec<&str> = head.iter().map(String::as_str).collect();
        let preamble = Preamble::parse(&refs[..4]).map_err(failed)?;
        Ok(Shard {
            path: path.to_path_buf(),
            preamble,
            header: head[4].clone(),
            lines,
            line: 5,
        })
    }

    /// The next row's line, if any.
    fn next_row(&mut self) -> Result<Option<String>, CliError> {
        match self.lines.next() {
            None => Ok(None),
            Some(Ok(line)) => {
                self.line += 1;
                Ok(Some(line))
            }
            Some(Err(e)) => Err(CliError::Failed(format!("{}: {e}", self.path.display()))),
        }
    }
}

/// The shards in shard order, checked to be all of one sweep.
fn open_all(files: &[PathBuf]) -> Result<Vec<Shard>, CliError> {
    let mut shards = files
        .iter()
        .map(|f| Shard::open(f))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &shards[0];
    let count = first.preamble.shard.1;
    for s in &shards[1..] {
        let (a, b) = (&first.preamble, &s.preamble);
        let differs = if a.sweep != b.sweep {
            Some(("sweep", &a.sweep, &b.sweep))
        } else if a.parameters != b.parameters {
            Some(("parameters", &a.parameters, &b.parameters))
        } else if a.settings != b.settings {
            Some(("settings", &a.settings, &b.settings))
        } else if first.header != s.header {
            Some(("columns", &first.header, &s.header))
        } else {
            None
        };
        if let Some((what, x, y)) = differs {
            return Err(CliError::Failed(format!(
                "{} and {} are not shards of one sweep: their {what} differ (`{x}` and `{y}`)",
                first.path.display(),
                s.path.display()
            )));
        }
        if b.shard.1 != count {
            return Err(CliError::Failed(format!(
                "{} is shard {}/{}, {} shard {}/{count}: not one sharding",
                s.path.display(),
                b.shard.0,
                b.shard.1,
                first.path.display(),
                a.shard.0
            )));
        }
    }
    shards.sort_by_key(|s| s.preamble.shard.0);
    for pair in shards.windows(2) {
        if pair[0].preamble.shard.0 == pair[1].preamble.shard.0 {
            return Err(CliError::Failed(format!(
                "shard {}/{count} is given twice: {} and {}",
                pair[0].preamble.shard.0,
                pair[0].path.display(),
                pair[1].path.display()
            )));
        }
    }
    let present: Vec<usize> = shards.iter().map(|s| s.preamble.shard.0).collect();
    let missing: Vec<String> = (1..=count)
        .filter(|i| !present.contains(i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(CliError::Failed(format!(
            "shard{} {} of this sweep {} missing",
            if missing.len() == 1 { "" } else { "s" },
            missing.join(", "),
            if missing.len() == 1 { "is" } else { "are" }
        )));
    }
    Ok(shards)
}

/// The runs of the sweep from its `parameters` line (for the figures).
fn runs_of(parameters: &str) -> Result<Runs, String> {
    let words: Vec<&str> = parameters.split_whitespace().collect();
    let mut swept = Vec::new();
    let mut design = Design::Product;
    let mut k = 0;
    while k < words.len() {
        if words[k] == "samples" && k + 3 < words.len() + 1 {
            let samples = words.get(k + 1).and_then(|w| w.parse().ok());
            let seed = words.get(k + 3).and_then(|w| w.parse().ok());
            match (samples, seed) {
                (Some(samples), Some(seed)) => design = Design::LatinHypercube { samples, seed },
                _ => return Err(format!("cannot read `{parameters}`")),
            }
            k += 4;
        } else {
            swept.push(spec::parse_param(words[k])?);
            k += 1;
        }
    }
    Runs::new(swept, design)
}

/// `camchain merge`.
pub fn run(args: &MergeArgs) -> Result<(), CliError> {
    let mut shards = open_all(&args.files)?;
    let preamble = shards[0].preamble.clone();
    let total = preamble.runs().ok_or_else(|| {
        CliError::Failed("the first line does not give the number of runs".into())
    })?;
    let runs = runs_of(&preamble.parameters).map_err(CliError::Failed)?;
    let names: Vec<String> = runs.swept.iter().map(|s| s.name.clone()).collect();
    if shards[0].header != table::header(&names).join(",") {
        return Err(CliError::Failed(format!(
            "{}: the columns are not those of this version's sweep CSV",
            shards[0].path.display()
        )));
    }
    let plotted = super::plotted_metrics(&args.metric)?;
    let model = preamble
        .sweep
        .strip_prefix("camchain sweep of ")
        .and_then(|s| s.split(" (").next())
        .unwrap_or("model")
        .to_string();
    // Held until the merged files are written: no other run writes them meanwhile.
    let mut locks: Vec<output::Lock> = Vec::new();
    let dir = match (&args.out, &args.csv) {
        (Some(dir), _) => Some(dir.clone()),
        (None, Some(_)) => None,
        (None, None) => Some(PathBuf::from(crate::args::DEFAULT_OUT)),
    };
    if let Some(dir) = &dir {
        locks.push(output::create_dir(dir).map_err(CliError::Failed)?);
    }
    let csv = match &args.csv {
        Some(p) if p.as_os_str() == "-" => None,
        Some(p) => {
            locks.extend(output::claim(p).map_err(CliError::Failed)?);
            Some(p.clone())
        }
        None => dir.as_ref().map(|d| d.join(format!("{model}_sweep.csv"))),
    };
    let count = shards.len();
    let mut plot = PlotData::new(&plotted);
    let metric_index: Vec<usize> = plotted
        .iter()
        .filter_map(|m| table::METRICS.iter().position(|(n, _)| n == m))
        .collect();
    let columns = names.len() + 2;
    let mut failed = 0;
    let mut write_rows =
        |out: &mut dyn Write, plot: &mut PlotData, failed: &mut usize| -> Result<(), CliError> {
            let merged = Preamble {
                shard: (1, 1),
                ..preamble.clone()
            };
            let io =
                |e: std::io::Error| CliError::Failed(format!("cannot write the merged CSV: {e}"));
            merged.write(out).map_err(io)?;
            writeln!(out, "{}", shards[0].header).map_err(io)?;
            for run in 0..total {
                let shard = &mut shards[run % count];
                let here = format!("{}:{}", shard.path.display(), shard.line + 1);
                let Some(line) = shard.next_row()? else {
                    return Err(CliError::Failed(format!(
                        "{here}: run {run} is missing (the file ends; was this shard interrupted?)"
                    )));
                };
                let cells = table::split(&line);
                if cells.first().and_then(|c| c.parse::<usize>().ok()) != Some(run) {
                    return Err(CliError::Failed(format!(
                        "{here}: expected run {run}, found `{}`",
                        cells.first().map_or("", String::as_str)
                    )));
                }
                let values: Vec<f64> = cells[1..columns - 1]
                    .iter()
                    .map(|c| c.parse().unwrap_or(f64::NAN))
                    .collect();
                *failed += usize::from(cells.get(columns - 1).is_some_and(|s| s == "failed"));
                let metrics = metric_index
                    .iter()
                    .map(|&k| cells.get(columns + k).and_then(|c| c.parse().ok()))
                    .collect();
                plot.add_values(values, metrics);
                writeln!(out, "{line}").map_err(io)?;
            }
            for shard in shards.iter_mut() {
                if shard.next_row()?.is_some() {
                    return Err(CliError::Failed(format!(
                        "{}:{}: a row beyond the sweep's {total} runs (repeated or foreign)",
                        shard.path.display(),
                        shard.line
                    )));
                }
            }
            Ok(())
        };
    let saved = match &csv {
        None => {
            let stdout = std::io::stdout();
            let mut out = stdout.lock();
            write_rows(&mut out, &mut plot, &mut failed)?;
            None
        }
        Some(path) => {
            let mut result = Ok(());
            let written = output::write_file(path, |out| {
                result = write_rows(out, &mut plot, &mut failed);
                match &result {
                    Ok(()) => Ok(()),
                    Err(e) => Err(std::io::Error::other(e.to_string())),
                }
            });
            result?;
            written.map_err(CliError::Failed)?;
            Some(path.clone())
        }
    };
    let drawn = match (&dir, args.no_plots, plot.complete) {
        (Some(dir), false, true) => figures::draw_runs(dir, &model, &runs, &plot)
            .map_err(|e| CliError::Failed(format!("figures: {e}")))?,
        _ => Vec::new(),
    };
    if !args.quiet {
        let mut text = format!(
            "merged {count} shards of the sweep of {model}: {total} runs, {failed} failed\n"
        );
        if let Some(path) = saved {
            text.push_str(&format!("  wrote {}\n", path.display()));
        }
        if !drawn.is_empty() {
            let names: Vec<String> = drawn
                .iter()
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect();
            text.push_str(&format!("  wrote figures: {}\n", names.join(", ")));
        }
        if csv.is_none() {
            eprint!("{text}");
        } else {
            print!("{text}");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::runs_of;
    use crate::sweep::spec::Design;

    #[test]
    fn the_parameters_line_gives_back_the_runs() {
        let runs = runs_of("swing=-0.5:0.5:21 k3=20,40,80").expect("reads");
        assert_eq!(runs.len(), 63);
        let lhs = runs_of("k2=5:30 k4=5:30 samples 200 seed 3").expect("reads");
        assert_eq!(
            lhs.design,
            Design::LatinHypercube {
                samples: 200,
                seed: 3
            }
        );
        assert_eq!(lhs.len(), 200);
        assert!(runs_of("k2=5:30 samples x seed 3").is_err());
    }
}
