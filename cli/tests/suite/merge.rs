//! `camchain merge` given damaged or hostile shards (issue 25): every row is checked against
//! the sweep its `#` lines define, each damage is one line naming file, line and column,
//! nothing is written outside what the command line names, no input makes it panic, and
//! randomly damaged shards never merge into anything but the undamaged result.

use crate::common;

use common::{camchain, scratch};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A sweep's shards, written once for every test of this module.
struct Fixture {
    /// Where the shards are (read only).
    dir: PathBuf,
    /// The shards' file names, in shard order.
    shards: Vec<String>,
    /// The merge of the undamaged shards.
    merged: Vec<u8>,
}

/// The unreachable-cam fixture with the drive's rate as a parameter: from a rate of about
/// 0.52 rad/s the tip loses the cam before t = 2 s, so the sweep has failed rows.
const RATE_MODEL: &str = r#"(
    name: "unreachable_rate",
    parameters: [(name: "rate", value: 0.2, unit: "rad/s", min: 0.0)],
    bodies: [
        (name: "link1", parent: "ground", mass: 1.0, com: (0.2, 0.0, 0.0), inertia: Izz(0.02),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.0, 0.5, 0.0), coordinate: "q1",
                 prescribed: "-PI/2 + rate*t")),
        (name: "link2", parent: "link1", mass: 0.5, com: (0.15, 0.0, 0.0), inertia: Izz(0.005),
         joint: (kind: Revolute, axis: (0.0, 0.0, 1.0), anchor: (0.4, 0.0, 0.0), coordinate: "q2",
                 spring: (damping: 0.1))),
    ],
    markers: [(name: "A", body: "link2", position: (0.3, 0.0, 0.0))],
    contacts: [(marker: "A", profile: "0.0*x")],
    initial: (q: {"q1": -1.5707963267948966, "q2": 0.8}, hold: ["q1"]),
    simulation: (t_end: 2.0, dt_out: 0.01),
)"#;

/// Runs `camchain sweep` with `args` and `--shard I/N --csv partI.csv` for every shard,
/// then merges them.
fn sweep_in_shards(dir: &Path, args: &[&str], count: usize) -> Fixture {
    let mut shards = Vec::new();
    for i in 1..=count {
        let file = format!("part{i}.csv");
        let shard = format!("{i}/{count}");
        let mut all = vec!["sweep"];
        all.extend(args);
        all.extend(["--shard", &shard, "--csv", &file, "-q"]);
        let out = camchain(dir, &all);
        // 0, or 3 and up: runs failed (their rows have the error).
        assert!(
            matches!(out.status.code(), Some(0 | 3..=127)),
            "{}",
            text(&out.stderr)
        );
        shards.push(file);
    }
    let mut all = vec!["merge"];
    all.extend(shards.iter().map(String::as_str));
    all.extend(["--csv", "merged.csv", "-q"]);
    let out = camchain(dir, &all);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    let merged = fs::read(dir.join("merged.csv")).expect("merged");
    Fixture {
        dir: dir.to_path_buf(),
        shards,
        merged,
    }
}

/// paper_concave over two parameters, 10 runs in 3 shards (rows of 18 cells).
fn grid() -> &'static Fixture {
    static GRID: OnceLock<Fixture> = OnceLock::new();
    GRID.get_or_init(|| {
        let dir = scratch("merge-fixture-grid");
        let args = [
            "paper_concave",
            "--param",
            "swing=-0.2:0.2:5",
            "--param",
            "c3=0.5,1.5",
            "--t-end",
            "0.2",
        ];
        sweep_in_shards(&dir, &args, 3)
    })
}

/// A model file over one parameter, 5 runs in 2 shards, 3 of them failed.
fn failing() -> &'static Fixture {
    static FAILING: OnceLock<Fixture> = OnceLock::new();
    FAILING.get_or_init(|| {
        let dir = scratch("merge-fixture-failing");
        fs::write(dir.join("rate.ron"), RATE_MODEL).expect("write");
        let args = ["rate.ron", "--param", "rate=0.2,0.8,0.4,1.6,3.2"];
        let fixture = sweep_in_shards(&dir, &args, 2);
        let merged = text(&fixture.merged);
        assert_eq!(merged.matches(",failed,").count(), 3, "{merged}");
        fixture
    })
}

/// A test's directory with copies of the fixture's shards.
fn copy(fixture: &Fixture, name: &str) -> PathBuf {
    let dir = scratch(name);
    for shard in &fixture.shards {
        fs::copy(fixture.dir.join(shard), dir.join(shard)).expect("copy");
    }
    dir
}

/// `camchain merge part1.csv … --csv merged.csv` in `dir`.
fn merge(dir: &Path, fixture: &Fixture) -> Output {
    let mut args = vec!["merge"];
    args.extend(fixture.shards.iter().map(String::as_str));
    args.extend(["--csv", "merged.csv"]);
    camchain(dir, &args)
}

/// The merge failed with one line, exit code 1, containing `phrase`, and wrote nothing.
fn refused(dir: &Path, out: &Output, phrase: &str) {
    let err = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.starts_with("error: "), "{err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.contains(phrase), "`{phrase}` in {err}");
    assert!(!dir.join("merged.csv").exists(), "nothing written");
}

/// Replaces line `line` (1-based) of `path` by what `edit` makes of it.
fn edit_line(path: &Path, line: usize, edit: impl Fn(&str) -> String) {
    let content = fs::read_to_string(path).expect("read");
    let lines: Vec<String> = content
        .lines()
        .enumerate()
        .map(|(k, l)| {
            if k + 1 == line {
                edit(l)
            } else {
                l.to_string()
            }
        })
        .collect();
    fs::write(path, lines.join("\n") + "\n").expect("write");
}

/// Replaces cell `cell` (0-based) of line `line` of `path` (rows without quotes only).
fn edit_cell(path: &Path, line: usize, cell: usize, value: &str) {
    edit_line(path, line, |l| {
        let mut cells: Vec<&str> = l.split(',').collect();
        cells[cell] = value;
        cells.join(",")
    });
}

// Line 6 of part2.csv is the first row of shard 2/3: run 1, cells run, swing, c3, status,
// max_normal_force, ….

#[test]
fn merge_refuses_a_truncated_row() {
    let fixture = grid();
    let dir = copy(fixture, "merge-truncated-row");
    edit_line(&dir.join("part2.csv"), 6, |l| {
        l.split(',').take(10).collect::<Vec<_>>().join(",")
    });
    let out = merge(&dir, fixture);
    refused(
        &dir,
        &out,
        "part2.csv:6: run 1's row has 10 of its 18 cells (a truncated row)",
    );
}

#[test]
fn merge_refuses_a_row_with_an_extra_cell() {
    let fixture = grid();
    let dir = copy(fixture, "merge-extra-cell");
    edit_line(&dir.join("part2.csv"), 7, |l| format!("{l},0.5,0.5"));
    let out = merge(&dir, fixture);
    refused(&dir, &out, "part2.csv:7: more than 18 cells");
}

#[test]
fn merge_refuses_a_parameter_value_foreign_to_the_sweep() {
    let fixture = grid();
    let dir = copy(fixture, "merge-foreign-value");
    // Run 1 is swing = -0.2, c3 = 1.5; 1.0 is no value of c3 in this sweep.
    edit_cell(&dir.join("part2.csv"), 6, 2, "1.0");
    let out = merge(&dir, fixture);
    refused(
        &dir,
        &out,
        "part2.csv:6: column `c3`: `1.0` is not run 1's value in this sweep, 1.5",
    );
    // A value of the sweep, but another run's, is refused too.
    let dir = copy(fixture, "merge-other-runs-value");
    edit_cell(&dir.join("part2.csv"), 6, 1, "-0.1");
    refused(&dir, &merge(&dir, fixture), "part2.csv:6: column `swing`");
}

#[test]
fn merge_refuses_a_bad_status() {
    let fixture = grid();
    let dir = copy(fixture, "merge-bad-status");
    edit_cell(&dir.join("part3.csv"), 6, 3, "GARBAGE");
    let out = merge(&dir, fixture);
    refused(
        &dir,
        &out,
        "part3.csv:6: column `status`: `GARBAGE` is neither `ok` nor `failed`",
    );
}

#[test]
fn merge_refuses_a_metric_that_is_not_a_number() {
    let fixture = grid();
    let dir = copy(fixture, "merge-not-a-number");
    edit_cell(&dir.join("part1.csv"), 7, 8, "not_a_number");
    let out = merge(&dir, fixture);
    refused(
        &dir,
        &out,
        "part1.csv:7: column `max_residual`: `not_a_number` is not a number",
    );
}

#[test]
fn merge_refuses_failed_rows_without_their_error_or_with_a_completed_runs_metrics() {
    let fixture = failing();
    let merged = text(&fixture.merged);
    // Find a failed run's row in its shard.
    let row = merged
        .lines()
        .find(|l| l.contains(",failed,"))
        .expect("a failed row");
    let run: usize = row
        .split(',')
        .next()
        .and_then(|r| r.parse().ok())
        .expect("run");
    let (shard, line) = (format!("part{}.csv", run % 2 + 1), 6 + run / 2);
    let dir = copy(fixture, "merge-failed-no-error");
    edit_line(&dir.join(&shard), line, |l| {
        let (head, _) = l.split_once(",failed,").expect("failed");
        let rest: Vec<&str> = l[head.len() + 8..].splitn(14, ',').collect();
        format!("{head},failed,{},", rest[..13].join(","))
    });
    refused(
        &dir,
        &merge(&dir, fixture),
        &format!("{shard}:{line}: column `error`: empty, but the run's status is `failed`"),
    );
    let dir = copy(fixture, "merge-failed-with-force");
    edit_cell(&dir.join(&shard), line, 3, "1.5");
    refused(
        &dir,
        &merge(&dir, fixture),
        &format!("{shard}:{line}: column `max_normal_force`: a value, but run {run} failed"),
    );
}

/// Rewrites line 1 of every shard of `dir` to say the sweep is of `model`.
fn rename_model(dir: &Path, fixture: &Fixture, model: &str) {
    for shard in &fixture.shards {
        edit_line(&dir.join(shard), 1, |l| {
            let (_, rest) = l.split_once(" (generated code)").expect("line 1");
            format!("# camchain sweep of {model} (generated code){rest}")
        });
    }
}

/// The names of the files in `dir`.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .expect("a directory")
        .map(|e| {
            e.expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    names.sort();
    names
}

#[test]
fn merge_never_writes_outside_out_whatever_the_header_says() {
    let fixture = grid();
    let dir = copy(fixture, "merge-header-path");
    let victim = dir.join("victim");
    fs::create_dir(&victim).expect("mkdir");
    let hostile = format!("{}/PWNED", victim.display());
    rename_model(&dir, fixture, &hostile);
    let mut args = vec!["merge"];
    args.extend(fixture.shards.iter().map(String::as_str));
    args.extend(["--out", "results", "--no-plots"]);
    let out = camchain(&dir, &args);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert!(listing(&victim).is_empty(), "{:?}", listing(&victim));
    // The documented rule: a path separator becomes `_`.
    let expected = format!("{}_sweep.csv", hostile.replace('/', "_"));
    assert_eq!(
        listing(&dir.join("results")),
        std::slice::from_ref(&expected)
    );
    let merged = fs::read_to_string(dir.join("results").join(&expected)).expect("read");
    assert!(
        merged.starts_with(&format!("# camchain sweep of {hostile} (generated code)")),
        "the first line is data, copied as it is: {merged}"
    );
    // A name with spaces and parentheses is kept; `..`, control characters and a
    // backslash are not.
    for (model, file) in [
        ("x (v2)", "x (v2)_sweep.csv"),
        ("..", "model_sweep.csv"),
        ("a\u{1b}]0;t\u{7}\\b", "a_]0_t__b_sweep.csv"),
    ] {
        let dir = copy(fixture, "merge-header-name");
        rename_model(&dir, fixture, model);
        let out = camchain(&dir, &args);
        assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
        assert_eq!(listing(&dir.join("results")), [file], "{model:?}");
    }
}

#[test]
fn merge_does_not_panic_on_a_row_holding_only_a_run_index() {
    let fixture = grid();
    let dir = copy(fixture, "merge-index-only");
    edit_line(&dir.join("part2.csv"), 7, |_| "4".to_string());
    let out = merge(&dir, fixture);
    refused(&dir, &out, "part2.csv:7: run 4's row has 1 of its 18 cells");
}

#[test]
fn a_damaged_shard_sends_nothing_to_standard_output() {
    let fixture = grid();
    let dir = copy(fixture, "merge-stdout");
    edit_cell(&dir.join("part3.csv"), 7, 3, "GARBAGE");
    let mut args = vec!["merge"];
    args.extend(fixture.shards.iter().map(String::as_str));
    args.extend(["--csv", "-"]);
    let out = camchain(&dir, &args);
    refused(&dir, &out, "part3.csv:7: column `status`");
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
}

#[test]
fn merge_refuses_unreadable_files_with_a_located_error() {
    let fixture = grid();
    let original = fs::read(fixture.dir.join("part2.csv")).expect("read");
    let head_end = original
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(4)
        .map(|(k, _)| k + 1)
        .expect("five lines");
    let with_row = |row: &[u8]| {
        let mut bytes = original[..head_end].to_vec();
        bytes.extend_from_slice(row);
        bytes
    };
    let mut binary = vec![0u8; 4096];
    let mut x = 0x2545_f491_4f6c_dd1d_u64;
    for b in &mut binary {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        *b = (x >> 24) as u8;
    }
    // One line longer than merge reads (4 MiB), without a line break.
    let huge = with_row(&vec![b'1'; (4 << 20) + 10]);
    let mut run_count = original.clone();
    let first_line = original.iter().position(|&b| b == b'\n').expect("a line");
    let line1 = text(&original[..first_line]).replace(": 10 runs", ": 11 runs");
    run_count.splice(..first_line, line1.bytes());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty", Vec::new(), "part2.csv: empty: not a sweep CSV"),
        ("binary", binary, "part2.csv:1:"),
        (
            "not UTF-8",
            with_row(b"1,-0.2,1.5,\xff\xfe\n"),
            "part2.csv:6: not UTF-8 text (byte 12 of the line)",
        ),
        (
            "header only",
            original[..head_end].to_vec(),
            "part2.csv:6: run 1 is missing (the file ends",
        ),
        (
            "cut inside the header",
            original[..head_end - 3].to_vec(),
            "part2.csv:5: the file ends inside this line",
        ),
        (
            "cut inside a row",
            original[..original.len() - 1].to_vec(),
            "part2.csv:8: the file ends inside this line",
        ),
        (
            "cut after a line of the # lines",
            original[..first_line + 1].to_vec(),
            "part2.csv:2: the file ends after 1 lines",
        ),
        (
            "a huge line",
            huge,
            "part2.csv:6: longer than 4194304 bytes",
        ),
        (
            "another run count",
            run_count,
            "are not shards of one sweep",
        ),
    ];
    for (what, bytes, phrase) in cases {
        let dir = copy(fixture, "merge-unreadable");
        fs::write(dir.join("part2.csv"), &bytes).expect("write");
        let out = merge(&dir, fixture);
        assert_ne!(out.status.code(), Some(101), "{what}: a panic");
        refused(&dir, &out, phrase);
    }
}

#[test]
fn merge_refuses_a_run_count_the_parameters_do_not_make() {
    let fixture = grid();
    let dir = copy(fixture, "merge-run-count");
    for shard in &fixture.shards {
        edit_line(&dir.join(shard), 1, |l| l.replace(": 10 runs", ": 20 runs"));
    }
    let out = merge(&dir, fixture);
    refused(
        &dir,
        &out,
        "part1.csv:3: the parameters make 10 runs, the first line says 20",
    );
}

#[test]
fn shards_with_crlf_line_breaks_merge_into_the_same_csv() {
    let fixture = grid();
    let dir = copy(fixture, "merge-crlf");
    let path = dir.join("part2.csv");
    let content = fs::read_to_string(&path).expect("read");
    fs::write(&path, content.replace('\n', "\r\n")).expect("write");
    let out = merge(&dir, fixture);
    assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
    assert_eq!(
        fs::read(dir.join("merged.csv")).expect("merged"),
        fixture.merged
    );
}

#[test]
fn a_shard_read_from_a_pipe_is_checked_as_it_is_merged() {
    // A FIFO cannot be read twice: its rows are checked as they are written, and the
    // output file takes its name only once every row passed.
    let fixture = grid();
    let pristine = fs::read(fixture.dir.join("part2.csv")).expect("read");
    let mut damaged = text(&pristine).into_bytes();
    let at = text(&damaged).rfind(",ok,").expect("an ok row");
    damaged.splice(at..at + 4, b",GARBAGE,".iter().copied());
    for (bytes, expected) in [(pristine, Some(&fixture.merged)), (damaged, None)] {
        let dir = copy(fixture, "merge-fifo");
        let fifo = dir.join("part2.csv");
        fs::remove_file(&fifo).expect("remove");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo runs");
        assert!(made.success());
        // The writer's open waits for merge to open the FIFO; it ends with the test
        // process if merge never did.
        let writer = std::thread::spawn(move || fs::write(&fifo, bytes));
        let out = merge(&dir, fixture);
        match expected {
            Some(merged) => {
                assert_eq!(out.status.code(), Some(0), "{}", text(&out.stderr));
                assert_eq!(&fs::read(dir.join("merged.csv")).expect("merged"), merged);
            }
            None => {
                refused(&dir, &out, "part2.csv:8: column `status`: `GARBAGE`");
                assert_eq!(listing(&dir), fixture.shards, "no temporary file left");
            }
        }
        writer.join().expect("the writer").expect("written");
    }
}

/// SplitMix64: a small seeded generator, the same cases on every machine.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }
}

/// A line's cells as they are written (quotes kept), split at the commas outside quotes.
fn raw_cells(line: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut quoted = false;
    for c in line.chars() {
        if c == '"' {
            quoted = !quoted;
        }
        if c == ',' && !quoted {
            cells.push(String::new());
        } else if let Some(cell) = cells.last_mut() {
            cell.push(c);
        }
    }
    cells
}

/// The damages the property test makes.
const DAMAGES: [&str; 5] = [
    "truncate",
    "drop a row",
    "duplicate a row",
    "widen",
    "alter",
];

/// `bytes` (a shard) damaged by `damage`, at places `rng` draws.
///
/// An altered cell gets a value the sweep cannot have written there: another run index,
/// parameter value or status, a metric that is not a number in the sweep's form, an error
/// on a completed run or none on a failed one. A metric changed into another well-formed
/// number, or a failed run's message into another message, is not damage a shard can show
/// (the format has no checksum), so it is not drawn.
fn damaged(bytes: &[u8], damage: &str, rng: &mut Rng) -> Vec<u8> {
    if damage == "truncate" {
        return bytes[..rng.below(bytes.len() + 1)].to_vec();
    }
    let content = std::str::from_utf8(bytes).expect("a sweep writes UTF-8");
    let mut lines: Vec<String> = content.lines().map(String::from).collect();
    let rows = lines.len() - 5;
    assert!(rows > 0, "every shard of the fixtures has rows");
    let k = 5 + rng.below(rows);
    match damage {
        "drop a row" => {
            lines.remove(k);
        }
        "duplicate a row" => {
            let row = lines[k].clone();
            let at = 5 + rng.below(rows + 1);
            lines.insert(at, row);
        }
        "widen" => {
            let mut cells = raw_cells(&lines[k]);
            let at = rng.below(cells.len() + 1);
            cells.insert(at, rng.pick(&["", "0", "0.5", "ok"]).to_string());
            lines[k] = cells.join(",");
        }
        _ => {
            let mut cells = raw_cells(&lines[k]);
            let width = cells.len();
            let c = rng.below(width);
            let old = cells[c].clone();
            let failed = cells[width - 15] == "failed";
            cells[c] = match c {
                0 => {
                    let run: usize = old.parse().expect("a run index");
                    let other = [run + 1, run.wrapping_sub(1), run + 2, run * 10 + 1];
                    other[rng.below(other.len())].to_string()
                }
                c if c < width - 15 => rng
                    .pick(&["-0.1", "0.5", "1.0", "0.30000000000000004"])
                    .to_string(),
                c if c == width - 15 => rng
                    .pick(&["GARBAGE", "OK", if failed { "ok" } else { "failed" }])
                    .to_string(),
                c if c == width - 1 => {
                    if failed {
                        String::new()
                    } else {
                        "boom".to_string()
                    }
                }
                _ => {
                    let token = rng.pick(&["not_a_number", "1.2.3", "x", "+", "\""]);
                    match rng.below(3) {
                        0 => token.to_string(),
                        1 => format!("{old}{token}"),
                        _ => format!("{token}{old}"),
                    }
                }
            };
            if cells[c] == old {
                // The same value again (a run index 0 minus 1 wrapped to itself cannot be,
                // but a listed value can): no damage.
                cells[c] = format!("{old}x");
            }
            lines[k] = cells.join(",");
        }
    }
    (lines.join("\n") + "\n").into_bytes()
}

#[test]
fn randomly_damaged_shards_never_merge_into_another_result() {
    // 250 cases: each runs the binary once (a few milliseconds, about 1.5 s in all); the
    // damages cycle so that each is drawn 50 times.
    const CASES: usize = 250;
    let fixtures = [grid(), failing()];
    let dir = scratch("merge-property");
    let mut rng = Rng(25);
    let mut outcomes = vec![(0usize, 0usize); DAMAGES.len()];
    for case in 0..CASES {
        let kind = case % DAMAGES.len();
        let fixture = fixtures[rng.below(fixtures.len())];
        let victim = rng.below(fixture.shards.len());
        let original = fs::read(fixture.dir.join(&fixture.shards[victim])).expect("read");
        let bytes = damaged(&original, DAMAGES[kind], &mut rng);
        fs::write(dir.join("damaged.csv"), &bytes).expect("write");
        let _ = fs::remove_file(dir.join("m.csv"));
        let mut args = vec!["merge".to_string()];
        for (k, shard) in fixture.shards.iter().enumerate() {
            args.push(if k == victim {
                "damaged.csv".to_string()
            } else {
                fixture.dir.join(shard).display().to_string()
            });
        }
        args.extend(["--csv", "m.csv", "-q"].map(String::from));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = camchain(&dir, &args);
        let err = text(&out.stderr);
        let what = format!(
            "case {case}, {} of {}:\n{}\n{err}",
            DAMAGES[kind],
            fixture.shards[victim],
            text(&bytes)
        );
        match out.status.code() {
            Some(0) => {
                let merged = fs::read(dir.join("m.csv")).expect("written");
                assert!(merged == fixture.merged, "another result: {what}");
                outcomes[kind].0 += 1;
            }
            Some(1) => {
                assert_eq!(err.lines().count(), 1, "{what}");
                assert!(err.contains("damaged.csv"), "names the file: {what}");
                assert!(!dir.join("m.csv").exists(), "nothing written: {what}");
                outcomes[kind].1 += 1;
            }
            code => panic!("exit code {code:?}: {what}"),
        }
    }
    // Every damage but truncation changes the rows: always refused. A truncation is
    // harmless only when it cuts nothing (at the file's end), which few of 50 draws do.
    for (kind, (accepted, refused)) in outcomes.iter().enumerate() {
        assert_eq!(accepted + refused, CASES / DAMAGES.len());
        if DAMAGES[kind] == "truncate" {
            assert!(*refused >= 45, "{}: {accepted} accepted", DAMAGES[kind]);
        } else {
            assert_eq!(*accepted, 0, "{}", DAMAGES[kind]);
        }
    }
}
