//! `camchain merge`: the shards of one sweep joined into its whole CSV.
//!
//! Checked before anything is written: every file is a sweep CSV, all of one sweep (same
//! model, parameters, settings and header), with one shard count N and every shard 1…N
//! exactly once, and the sweep its first line names is the one its parameters line defines
//! (as many runs, the header's columns). Then the rows are read in run order, one from each
//! shard in turn (shard I holds runs I − 1, I − 1 + N, …, in order), and every row is checked
//! against what the sweep writes for that run (module [`super::table::rows`]): its cells, its run
//! index and parameter values regenerated from the parameters line, its status and metrics.
//! A missing, repeated, truncated, widened or altered row is an error naming the file, the
//! line and the column; memory stays flat (one line at a time, each at most
//! [`read::MAX_LINE`] bytes).
//!
//! When every shard is a regular file, all of them are read and checked once before the
//! output is opened, then read again to write it: a damaged shard leaves no output at all,
//! not even on standard output or a FIFO. Shards that cannot be read twice (pipes) are
//! checked as they are written; the output then ends at the damage and the exit code is 1
//! (a regular output file is still never replaced by an incomplete one).
//!
//! The output is `--csv FILE` as given, or `<model>_sweep.csv` inside `--out DIR` (default
//! `out`), the model's name made a plain file name ([`name::merged_csv`]).

mod name;
mod read;

use super::spec::{self, Design, Runs, Swept};
use super::table::rows::{RowCheck, escaped, shown};
use super::table::{self, METRICS, Preamble};
use super::{PlotData, figures};
use crate::CliError;
use crate::args::MergeArgs;
use crate::output;
use read::ShardFile;
use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The longest message merge prints (characters): a message quotes the files' text.
const MAX_MESSAGE: usize = 2000;

/// The sweep the shards are of, from their `#` lines.
struct Sweep {
    /// The first shard's `#` lines (the same in every shard but for the shard line).
    preamble: Preamble,
    /// The header line.
    header: String,
    /// The model's name as the first line gives it.
    model: String,
    /// The runs, regenerated from the parameters line.
    runs: Runs,
    /// The number of shards.
    count: usize,
}

impl Sweep {
    fn total(&self) -> usize {
        self.runs.len()
    }
}

/// The swept parameters and design from a sweep's `parameters` line (what
/// [`Runs::describe`] writes): `NAME=SPEC …`, then `samples S seed K` for a Latin
/// hypercube.
fn definition(parameters: &str) -> Result<(Vec<Swept>, Design), String> {
    let words: Vec<&str> = parameters.split_whitespace().collect();
    let (params, design) = match words.iter().position(|w| *w == "samples") {
        None => (&words[..], Design::Product),
        Some(k) => match &words[k..] {
            [_, samples, "seed", seed] => match (samples.parse(), seed.parse()) {
                (Ok(samples), Ok(seed)) => (&words[..k], Design::LatinHypercube { samples, seed }),
                _ => return Err("`samples S seed K` needs two whole numbers".to_string()),
            },
            _ => return Err("`samples` must end the line as `samples S seed K`".to_string()),
        },
    };
    let swept = params
        .iter()
        .map(|w| spec::parse_param(w))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((swept, design))
}

/// The runs of the sweep that `first`'s `#` lines describe, checked against its first line
/// and header; `bytes`: the shards' total size when every shard is a regular file (a bound
/// on the rows they can hold, checked before a Latin hypercube's points are drawn).
fn sweep_of(first: &ShardFile, count: usize, bytes: Option<u64>) -> Result<Sweep, String> {
    let path = first.path.display();
    let line1 = || format!("{path}:1: `{}`", shown(&first.preamble.sweep));
    let Some((model, _)) = first.preamble.model() else {
        return Err(format!(
            "{}: not `camchain sweep of MODEL (PATH): N runs`",
            line1()
        ));
    };
    let Some(total) = first.preamble.runs() else {
        return Err(format!("{}: the number of runs is missing", line1()));
    };
    let at3 = |e: String| format!("{path}:3: parameters: {e}");
    let (swept, design) = definition(&first.preamble.parameters).map_err(at3)?;
    let columns = table::header(&swept.iter().map(|s| s.name.clone()).collect::<Vec<_>>());
    if first.header != columns.join(",") {
        return Err(format!(
            "{path}:5: the header is not the columns of a sweep of {} (`{}`)",
            swept
                .iter()
                .map(|s| s.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            shown(&first.header)
        ));
    }
    if let Design::LatinHypercube { samples, .. } = design
        && samples != total
    {
        return Err(format!(
            "{path}:3: the parameters make {samples} runs, the first line says {total}"
        ));
    }
    // Every row has at least one byte per cell (its commas and line break).
    if let Some(bytes) = bytes {
        let room = bytes / columns.len() as u64;
        if total as u64 > room {
            return Err(format!(
                "{}: the shards ({bytes} bytes in all) cannot hold {total} rows of at least \
                 {} bytes each: rows are missing",
                line1(),
                columns.len()
            ));
        }
    }
    let runs = Runs::new(swept, design).map_err(at3)?;
    if runs.len() != total {
        return Err(format!(
            "{path}:3: the parameters make {} runs, the first line says {total}",
            runs.len()
        ));
    }
    Ok(Sweep {
        preamble: first.preamble.clone(),
        header: first.header.clone(),
        model: model.to_string(),
        runs,
        count,
    })
}

/// The shards in shard order, checked to be all of one sweep, and that sweep.
fn open_all(files: &[PathBuf], bytes: Option<u64>) -> Result<(Sweep, Vec<ShardFile>), String> {
    let mut shards = files
        .iter()
        .map(|f| ShardFile::open(f))
        .collect::<Result<Vec<_>, _>>()?;
    let Some(first) = shards.first() else {
        return Err("no shard given".to_string());
    };
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
            return Err(format!(
                "{} and {} are not shards of one sweep: their {what} differ (`{}` and `{}`)",
                first.path.display(),
                s.path.display(),
                shown(x),
                shown(y)
            ));
        }
        if b.shard.1 != count {
            return Err(format!(
                "{} is shard {}/{}, {} shard {}/{count}: not one sharding",
                s.path.display(),
                b.shard.0,
                b.shard.1,
                first.path.display(),
                a.shard.0
            ));
        }
    }
    shards.sort_by_key(|s| s.preamble.shard.0);
    for pair in shards.windows(2) {
        if pair[0].preamble.shard.0 == pair[1].preamble.shard.0 {
            return Err(format!(
                "shard {}/{count} is given twice: {} and {}",
                pair[0].preamble.shard.0,
                pair[0].path.display(),
                pair[1].path.display()
            ));
        }
    }
    if shards.len() != count {
        // The first few missing, found without counting to N (which may be huge).
        let present: Vec<usize> = shards.iter().map(|s| s.preamble.shard.0).collect();
        let mut missing = Vec::new();
        let mut next = 1;
        for &p in present.iter().chain([&(count + 1)]) {
            while next < p && missing.len() < 5 {
                missing.push(format!("{next}/{count}"));
                next += 1;
            }
            next = p + 1;
        }
        let absent = count - shards.len();
        let more = if absent > missing.len() {
            format!(" and {} more", absent - missing.len())
        } else {
            String::new()
        };
        return Err(format!(
            "shard{} {}{more} of this sweep {} missing",
            if absent == 1 { "" } else { "s" },
            missing.join(", "),
            if absent == 1 { "is" } else { "are" }
        ));
    }
    // Last: a Latin hypercube's points are drawn only for a complete set of shards.
    let sweep = sweep_of(&shards[0], count, bytes)?;
    Ok((sweep, shards))
}

/// The shards opened again for the second reading, each checked to begin as it did.
fn reopen(sweep: &Sweep, shards: &[ShardFile]) -> Result<Vec<ShardFile>, String> {
    shards
        .iter()
        .map(|old| {
            let new = ShardFile::open(&old.path)?;
            if new.preamble != old.preamble || new.header != sweep.header {
                return Err(format!(
                    "{}: changed while it was being merged",
                    old.path.display()
                ));
            }
            Ok(new)
        })
        .collect()
}

/// What a reading of the shards found.
struct Read {
    /// How many runs failed.
    failed: usize,
}

/// Reads every row of `shards` in run order, checks it, writes the merged CSV to `out`
/// (the `#` lines with shard `1/1`, the header, the rows as they are in the shards) and
/// keeps the plotted metrics in `plot`.
fn read_rows(
    sweep: &Sweep,
    shards: &mut [ShardFile],
    out: &mut dyn Write,
    mut plot: Option<&mut PlotData>,
) -> Result<Read, String> {
    let io = |e: io::Error| format!("cannot write the merged CSV: {e}");
    let merged = Preamble {
        shard: (1, 1),
        ..sweep.preamble.clone()
    };
    merged.write(out).map_err(io)?;
    writeln!(out, "{}", sweep.header).map_err(io)?;
    let check = RowCheck::new(&sweep.runs);
    let plotted: Vec<usize> = plot.as_ref().map_or_else(Vec::new, |p| {
        p.metrics
            .iter()
            .filter_map(|m| METRICS.iter().position(|(n, _)| n == m))
            .collect()
    });
    let total = sweep.total();
    let mut failed = 0;
    for run in 0..total {
        let shard = &mut shards[run % sweep.count];
        let Some(line) = shard.next_line()? else {
            return Err(format!(
                "{}: run {run} is missing (the file ends; was this shard interrupted?)",
                shard.next_place()
            ));
        };
        let row = check
            .check(&line, run)
            .map_err(|e| format!("{}: {e}", shard.place()))?;
        failed += usize::from(row.failed);
        if let Some(plot) = plot.as_deref_mut() {
            let metrics = plotted.iter().map(|&k| row.metrics[k]).collect();
            plot.add_values(row.values, metrics);
        }
        writeln!(out, "{line}").map_err(io)?;
    }
    for shard in shards.iter_mut() {
        if shard.has_more()? {
            return Err(format!(
                "{}: a row beyond the sweep's {total} runs (repeated or foreign)",
                shard.next_place()
            ));
        }
    }
    out.flush().map_err(io)?;
    Ok(Read { failed })
}

/// `camchain merge`.
pub fn run(args: &MergeArgs) -> Result<(), CliError> {
    merge(args).map_err(|e| match e {
        // One line, whatever text of the files it quotes.
        CliError::Failed(message) => CliError::Failed(escaped(&message, MAX_MESSAGE)),
        other => other,
    })
}

fn merge(args: &MergeArgs) -> Result<(), CliError> {
    let failed = CliError::Failed;
    let plotted = super::plotted_metrics(&args.metric)?;
    // Held until the merged files are written: no other run writes them meanwhile.
    let mut locks: Vec<output::Lock> = Vec::new();
    let dir = match (&args.out, &args.csv) {
        (Some(dir), _) => Some(dir.clone()),
        (None, Some(_)) => None,
        (None, None) => Some(PathBuf::from(crate::args::DEFAULT_OUT)),
    };
    if let Some(p) = args.csv.as_ref().filter(|p| p.as_os_str() != "-") {
        locks.extend(output::claim(p).map_err(failed)?);
    }
    // Regular files are read twice: checked entirely before anything is written.
    let sizes: Option<Vec<u64>> = args
        .files
        .iter()
        .map(|f| {
            fs::metadata(f)
                .ok()
                .filter(|m| m.is_file())
                .map(|m| m.len())
        })
        .collect();
    let bytes = sizes.as_ref().map(|s| s.iter().sum());
    let (mut sweep, mut shards) = open_all(&args.files, bytes).map_err(failed)?;
    // The shards do not record units: a built-in model's declarations give them (a model
    // file's figures have plain parameter names on their axes).
    if let Some(model) = camchain_models::by_name(&sweep.model) {
        for s in &mut sweep.runs.swept {
            if let Some(p) = model.info().parameters.iter().find(|p| p.name == s.name) {
                s.unit.clone_from(&p.unit);
            }
        }
    }
    if bytes.is_some() {
        read_rows(&sweep, &mut shards, &mut io::sink(), None).map_err(failed)?;
        shards = reopen(&sweep, &shards).map_err(failed)?;
    }
    if let Some(dir) = &dir {
        locks.push(output::create_dir(dir).map_err(failed)?);
    }
    let csv = match &args.csv {
        Some(p) if p.as_os_str() == "-" => None,
        Some(p) => Some(p.clone()),
        None => dir.as_ref().map(|d| d.join(name::merged_csv(&sweep.model))),
    };
    // The figures' data, kept only when there will be figures.
    let figures_dir = dir.as_ref().filter(|_| !args.no_plots);
    let mut plot = figures_dir.map(|_| PlotData::new(&plotted));
    let read = match &csv {
        None => {
            let stdout = io::stdout();
            let mut out = stdout.lock();
            read_rows(&sweep, &mut shards, &mut out, plot.as_mut()).map_err(failed)?
        }
        Some(path) => write_to(path, &sweep, &mut shards, plot.as_mut())?,
    };
    let model = shown(&sweep.model);
    let drawn = match (figures_dir, &plot) {
        (Some(dir), Some(plot)) if plot.complete => {
            figures::draw_runs(dir, &model, &sweep.runs, plot)
                .map_err(|e| failed(format!("figures: {e}")))?
        }
        _ => Vec::new(),
    };
    if !args.quiet {
        let mut text = format!(
            "merged {} of the sweep of {model}: {}, {} failed\n",
            crate::counted(sweep.count, "shard"),
            crate::counted(sweep.total(), "run"),
            read.failed
        );
        if let Some(path) = &csv {
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

/// The merged CSV written to `path` (through a temporary file renamed when complete).
fn write_to(
    path: &Path,
    sweep: &Sweep,
    shards: &mut [ShardFile],
    plot: Option<&mut PlotData>,
) -> Result<Read, CliError> {
    let mut result = None;
    let written = output::write_file(path, |out| {
        let read = read_rows(sweep, shards, out, plot);
        let failed = read.as_ref().err().map(|e| io::Error::other(e.clone()));
        result = Some(read);
        failed.map_or(Ok(()), Err)
    });
    match (result, written) {
        // A damaged shard: its message, not the file's.
        (Some(Err(e)), _) => Err(CliError::Failed(e)),
        (Some(Ok(read)), Ok(())) => Ok(read),
        (_, written) => {
            Err(CliError::Failed(written.err().unwrap_or_else(|| {
                format!("cannot write {}: not written", path.display())
            })))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::definition;
    use crate::sweep::spec::{Design, Runs, parse_param};

    fn runs_of(parameters: &str) -> Result<Runs, String> {
        let (swept, design) = definition(parameters)?;
        Runs::new(swept, design)
    }

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
        // What the sweep records reads back as the same runs, even from specs written with
        // spaces, and a Latin hypercube's points are the same.
        for (specs, design) in [
            (
                vec!["k3 = 20, 40 ,80", "swing=-0.5 : 0.5 : 3"],
                Design::Product,
            ),
            (
                vec!["k2=5:30", "k4= 1 : 2"],
                Design::LatinHypercube {
                    samples: 7,
                    seed: 11,
                },
            ),
        ] {
            let swept = specs.iter().map(|s| parse_param(s).expect(s)).collect();
            let runs = Runs::new(swept, design).expect("runs");
            assert_eq!(runs_of(&runs.describe()), Ok(runs));
        }
        for bad in [
            "k2=5:30 samples x seed 3",
            "k2=5:30 samples 3 seed",
            "k2=5:30 samples 3 sed 4",
            "k2=5:30 samples 3 seed 4 k4=1:2",
            "k2",
        ] {
            assert!(runs_of(bad).is_err(), "{bad}");
        }
    }
}
