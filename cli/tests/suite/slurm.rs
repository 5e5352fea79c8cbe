//! The cluster recipes of docs/sweeps.md, run for real: the Slurm job array and merge job of
//! `scripts/slurm/` on a single-node Slurm started here, and GNU parallel. Each merged CSV must
//! be the single-process sweep's, row for row (but for the wall time); a shard killed by
//! `scancel` mid-run must make the merge refuse, naming the missing shard.
//!
//! They need root and Debian's packages (`slurmctld`, `slurmd`, `slurm-client`, `munge`;
//! `parallel`), installed with apt-get when missing. Where that cannot be done (not root, no
//! apt-get, no package registry), each test says why and passes without running: the README's
//! test command runs them wherever it can, CI included.

use crate::common::scratch;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

const CAMCHAIN: &str = env!("CARGO_BIN_EXE_camchain");

/// The study: 24 runs of the paper's chain, 0.5 s each.
const MODEL: &str = "paper_concave";
const PARAMS: &str = "swing=-0.5:0.5:8 k3=20,40,80";
const OPTIONS: &str = "--t-end 0.5";

fn scripts() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("scripts")
        .join("slurm")
}

fn run(command: &mut Command) -> Output {
    command
        .output()
        .unwrap_or_else(|e| panic!("{command:?} cannot start: {e}"))
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Whether `program` is on the PATH (or in /usr/sbin, where Debian puts the daemons).
fn found(program: &str) -> bool {
    let path = std::env::var("PATH").unwrap_or_default();
    path.split(':')
        .chain(["/usr/sbin", "/sbin"])
        .any(|dir| Path::new(dir).join(program).is_file())
}

/// Why the test cannot run here, or `None` once `programs` are installed (by apt-get from
/// `packages` if missing).
fn unavailable(programs: &[&str], packages: &[&str]) -> Option<String> {
    if !cfg!(target_os = "linux") {
        return Some("not Linux".into());
    }
    // One apt-get at a time: the tests of this module run in parallel, and dpkg takes a lock.
    static APT: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _apt = APT
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if programs.iter().all(|p| found(p)) {
        return None;
    }
    let uid = run(Command::new("id").arg("-u"));
    if text(&uid.stdout).trim() != "0" {
        return Some(format!(
            "{programs:?} missing and not root (apt-get needs root)"
        ));
    }
    if !found("apt-get") {
        return Some(format!("{programs:?} missing and no apt-get"));
    }
    let install = |update: bool| {
        if update {
            let _ = run(Command::new("apt-get").args(["update", "-qq"]));
        }
        run(Command::new("apt-get")
            .args(["install", "-y", "-qq", "--no-install-recommends"])
            .args(packages)
            .env("DEBIAN_FRONTEND", "noninteractive"))
    };
    let first = install(false);
    if !first.status.success() && !install(true).status.success() {
        return Some(format!(
            "apt-get install {} failed: {}",
            packages.join(" "),
            text(&first.stderr).lines().last().unwrap_or("")
        ));
    }
    if programs.iter().all(|p| found(p)) {
        None
    } else {
        Some(format!("{programs:?} still missing after apt-get"))
    }
}

/// The study's CSV lines without the `wall_time` column (the one column that differs between
/// two runs of the same sweep).
fn without_wall_time(csv: &Path) -> Vec<String> {
    let body = fs::read_to_string(csv).unwrap_or_else(|e| panic!("{}: {e}", csv.display()));
    let mut column = None;
    body.lines()
        .map(|line| {
            if line.starts_with('#') {
                return line.to_string();
            }
            let cells: Vec<&str> = line.split(',').collect();
            let at = *column.get_or_insert_with(|| {
                cells
                    .iter()
                    .position(|c| *c == "wall_time")
                    .expect("a wall_time column")
            });
            let kept: Vec<&str> = cells
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != at)
                .map(|(_, c)| *c)
                .collect();
            kept.join(",")
        })
        .collect()
}

/// The same study in one process.
fn single_process(dir: &Path) -> Vec<String> {
    let csv = dir.join("single.csv");
    let mut args = vec!["sweep", MODEL];
    for spec in PARAMS.split(' ') {
        args.extend(["--param", spec]);
    }
    args.extend(OPTIONS.split(' '));
    let csv_arg = csv.display().to_string();
    args.extend(["--csv", &csv_arg, "--no-plots", "--quiet"]);
    let out = run(Command::new(CAMCHAIN).args(&args));
    assert!(out.status.success(), "{}", text(&out.stderr));
    without_wall_time(&csv)
}

/// A single-node Slurm of this test's own (munged, slurmctld, slurmd with their own
/// configuration, sockets, ports and state under `dir`), stopped by its process ids when
/// dropped.
struct Cluster {
    dir: PathBuf,
    conf: PathBuf,
}

impl Cluster {
    fn start(dir: &Path) -> Cluster {
        let run_dir = dir.join("daemons");
        for sub in ["state", "spool"] {
            fs::create_dir_all(run_dir.join(sub)).expect("daemon directories");
        }
        let key = run_dir.join("munge.key");
        let mut bytes = vec![0u8; 1024];
        std::io::Read::read_exact(
            &mut fs::File::open("/dev/urandom").expect("/dev/urandom"),
            &mut bytes,
        )
        .expect("random bytes");
        fs::write(&key, bytes).expect("munge key");
        let mode = run(Command::new("chmod").arg("600").arg(&key));
        assert!(mode.status.success());
        let socket = run_dir.join("munge.socket");
        let p = |name: &str| run_dir.join(name).display().to_string();
        let munged = run(Command::new("munged")
            .arg("--force")
            .arg(format!("--socket={}", socket.display()))
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--pid-file={}", p("munged.pid")))
            .arg(format!("--seed-file={}", p("munged.seed")))
            .arg(format!("--log-file={}", p("munged.log"))));
        assert!(munged.status.success(), "munged: {}", text(&munged.stderr));
        // Ports of this process's own, so that two test runs on one machine do not meet.
        let port = 20_000 + 2 * (std::process::id() % 10_000);
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let conf = run_dir.join("slurm.conf");
        fs::write(
            &conf,
            format!(
                "ClusterName=camchain\nSlurmctldHost=localhost\nSlurmctldPort={port}\n\
                 SlurmdPort={}\nSlurmUser=root\nSlurmdUser=root\nAuthType=auth/munge\n\
                 AuthInfo=socket={}\nCredType=cred/munge\nProctrackType=proctrack/linuxproc\n\
                 TaskPlugin=task/none\nSwitchType=switch/none\nMpiDefault=none\n\
                 ReturnToService=2\nSchedulerType=sched/builtin\n\
                 SchedulerParameters=batch_sched_delay=0,sched_min_interval=0\n\
                 SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\n\
                 StateSaveLocation={}\nSlurmdSpoolDir={}\nSlurmctldPidFile={}\n\
                 SlurmdPidFile={}\nSlurmctldLogFile={}\nSlurmdLogFile={}\n\
                 JobAcctGatherType=jobacct_gather/none\n\
                 AccountingStorageType=accounting_storage/none\n\
                 NodeName=localhost NodeAddr=127.0.0.1 CPUs={cpus} State=UNKNOWN\n\
                 PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP\n",
                port + 1,
                socket.display(),
                p("state"),
                p("spool"),
                p("slurmctld.pid"),
                p("slurmd.pid"),
                p("slurmctld.log"),
                p("slurmd.log"),
            ),
        )
        .expect("slurm.conf");
        let cluster = Cluster {
            dir: dir.to_path_buf(),
            conf,
        };
        let ctld = run(cluster.command("slurmctld").arg("-f").arg(&cluster.conf));
        assert!(ctld.status.success(), "slurmctld: {}", text(&ctld.stderr));
        let slurmd = run(cluster
            .command("slurmd")
            .arg("-f")
            .arg(&cluster.conf)
            .args(["-N", "localhost"]));
        assert!(slurmd.status.success(), "slurmd: {}", text(&slurmd.stderr));
        cluster.wait_until("the node is idle", Duration::from_secs(60), || {
            let out = run(cluster.command("sinfo").args(["-h", "-o", "%t"]));
            text(&out.stdout).trim() == "idle"
        });
        cluster
    }

    /// A Slurm command aimed at this cluster.
    fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        command
            .env("SLURM_CONF", &self.conf)
            .env("CAMCHAIN", CAMCHAIN)
            .current_dir(&self.dir);
        command
    }

    fn wait_until(&self, what: &str, limit: Duration, mut done: impl FnMut() -> bool) {
        let start = Instant::now();
        while !done() {
            assert!(
                start.elapsed() < limit,
                "waited {limit:?} for {what}; logs in {}",
                self.dir.join("daemons").display()
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// Whether job `id` is still queued or running.
    fn queued(&self, id: &str) -> bool {
        let out = run(self.command("squeue").args(["-h", "-j", id]));
        !text(&out.stdout).trim().is_empty()
    }

    /// Submits `sweep.sbatch` as the array tasks `tasks` of the study in `study`; the job id.
    fn submit_shards(&self, study: &Path, tasks: &str, shards: usize, params: &str) -> String {
        // Slurm opens the task's log before the script runs: its directory must exist.
        fs::create_dir_all(study).expect("the study's directory");
        let out = run(self
            .command("sbatch")
            .args(["--parsable", &format!("--array={tasks}"), "--export=ALL"])
            .arg(format!("--output={}/shard-%a.log", study.display()))
            .arg(scripts().join("sweep.sbatch"))
            .env("CAMCHAIN_DIR", study)
            .env("CAMCHAIN_MODEL", MODEL)
            .env("CAMCHAIN_SHARDS", shards.to_string())
            .env("CAMCHAIN_PARAMS", params)
            .env("CAMCHAIN_OPTIONS", OPTIONS));
        assert!(out.status.success(), "sbatch: {}", text(&out.stderr));
        text(&out.stdout)
            .trim()
            .split(';')
            .next()
            .unwrap_or("")
            .to_string()
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let daemons = self.dir.join("daemons");
        for name in ["slurmd.pid", "slurmctld.pid", "munged.pid"] {
            let Ok(pid) = fs::read_to_string(daemons.join(name)) else {
                continue;
            };
            let pid = pid.trim().to_string();
            let _ = Command::new("kill").args(["-TERM", &pid]).output();
            let alive = || Path::new("/proc").join(&pid).exists();
            let start = Instant::now();
            while alive() && start.elapsed() < Duration::from_secs(10) {
                std::thread::sleep(Duration::from_millis(50));
            }
            if alive() {
                let _ = Command::new("kill").args(["-KILL", &pid]).output();
            }
        }
    }
}

#[test]
fn a_slurm_job_array_and_its_merge_give_the_single_process_sweep() {
    let programs = ["munged", "slurmctld", "slurmd", "sbatch"];
    let packages = ["slurmctld", "slurmd", "slurm-client", "munge"];
    if let Some(why) = unavailable(&programs, &packages) {
        eprintln!("slurm test skipped: {why}");
        return;
    }
    let dir = scratch("slurm");
    let cluster = Cluster::start(&dir);

    // The recipe: 8 shards, 2 at a time, then the merge job, waited for with sbatch --wait.
    let study = dir.join("study");
    let submitted = run(cluster
        .command("bash")
        .arg(scripts().join("submit.sh"))
        .arg(&study)
        .args([MODEL, "8", "2", PARAMS, "--wait"])
        .env("CAMCHAIN_OPTIONS", OPTIONS));
    assert!(
        submitted.status.success(),
        "submit.sh: {}{}; merge log: {}",
        text(&submitted.stdout),
        text(&submitted.stderr),
        fs::read_to_string(study.join("logs/merge.log")).unwrap_or_default()
    );
    let merged = without_wall_time(&study.join("sweep.csv"));
    let single = single_process(&dir);
    assert!(merged.len() > 24, "{merged:?}");
    assert_eq!(merged, single, "the merged shards against one process");

    // A shard killed by scancel while it runs: 2 shards of a longer study (8000 runs);
    // shard 2 completes, shard 1 is cancelled as soon as its rows start to stream.
    let killed = dir.join("killed");
    let long = "swing=-0.5:0.5:40 k3=20:80:200";
    let second = cluster.submit_shards(&killed, "2", 2, long);
    cluster.wait_until("shard 2", Duration::from_secs(120), || {
        !cluster.queued(&second)
    });
    assert!(
        killed.join("shards/shard-2.csv").is_file(),
        "shard 2 completed"
    );
    let first = cluster.submit_shards(&killed, "1", 2, long);
    let partial = killed.join("shards/shard-1.partial.csv");
    cluster.wait_until("shard 1 to run", Duration::from_secs(60), || {
        partial.is_file()
    });
    let cancel = run(cluster.command("scancel").arg(&first));
    assert!(cancel.status.success(), "scancel: {}", text(&cancel.stderr));
    cluster.wait_until("shard 1 to stop", Duration::from_secs(60), || {
        !cluster.queued(&first)
    });
    assert!(
        !killed.join("shards/shard-1.csv").exists(),
        "a cancelled shard has no complete CSV"
    );
    assert!(partial.is_file(), "its rows so far are kept");
    let merge = run(cluster
        .command("bash")
        .arg(scripts().join("merge.sbatch"))
        .env("CAMCHAIN_DIR", &killed));
    assert_eq!(merge.status.code(), Some(1));
    let said = text(&merge.stderr);
    assert!(
        said.contains("shard 1/2 of this sweep is missing"),
        "{said}"
    );
    assert!(!killed.join("sweep.csv").exists(), "nothing merged");
    drop(cluster);
    let _ = fs::remove_dir_all(&dir);
}

/// docs/sweeps.md's alternative without a scheduler: GNU parallel runs the shards, merge
/// joins them.
#[test]
fn gnu_parallel_shards_and_their_merge_give_the_single_process_sweep() {
    if let Some(why) = unavailable(&["parallel"], &["parallel"]) {
        eprintln!("GNU parallel test skipped: {why}");
        return;
    }
    let dir = scratch("parallel");
    let shards = dir.join("shards");
    fs::create_dir_all(&shards).expect("shards");
    let params: Vec<String> = PARAMS.split(' ').map(|p| format!("--param {p}")).collect();
    let line = format!(
        "parallel --will-cite --halt now,fail=1 -j 2 {CAMCHAIN} sweep {MODEL} {} {OPTIONS} \
         --shard {{}}/8 --csv {}/shard-{{}}.csv --no-plots --quiet ::: 1 2 3 4 5 6 7 8 && \
         {CAMCHAIN} merge {}/shard-*.csv --csv {}/sweep.csv --no-plots --quiet",
        params.join(" "),
        shards.display(),
        shards.display(),
        dir.display()
    );
    let out = run(Command::new("bash").args(["-c", &line]));
    assert!(out.status.success(), "{line}: {}", text(&out.stderr));
    assert_eq!(
        without_wall_time(&dir.join("sweep.csv")),
        single_process(&dir)
    );
    let _ = fs::remove_dir_all(&dir);
}
