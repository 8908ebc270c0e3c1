//! Process harness for the interop tests: finds our release binaries and the peers, spawns them with
//! captured output, waits for lines with bounded timeouts, and kills what is left on drop.
//!
//! A missing tool (peer, binary, network namespace) fails the test when `CI=true` and skips it (with a
//! message on stderr) otherwise.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Condvar, Mutex, OnceLock};
use std::thread;
use std::time::{Duration, Instant};

/// A participant of ours on `lo`, announcing itself every 200 ms (for tests that use the library directly).
pub fn loopback_participant(domain: u32) -> dds_runtime::prelude::DomainParticipant {
    dds_runtime::prelude::DomainParticipant::builder()
        .domain_id(domain)
        .interface("lo")
        .spdp_interval(Duration::from_millis(200))
        .build()
        .expect("participant")
}

/// The workspace root (`tests/..`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// Checks a precondition: `Ok(())` when met; otherwise panics in CI and returns `Err` (skip) locally.
pub fn require(ok: bool, what: &str) -> Result<(), Skip> {
    if ok {
        return Ok(());
    }
    if in_ci() {
        panic!("interop prerequisite missing: {what}");
    }
    eprintln!("SKIP (not in CI): {what}");
    Err(Skip)
}

/// A test skipped because a tool is missing (only outside CI).
#[derive(Debug)]
pub struct Skip;

/// Every test runs its programs only inside `scripts/isolated` (the network rule).
pub fn require_netns() -> Result<(), Skip> {
    require(
        std::env::var("DDS_IN_NETNS").is_ok_and(|v| v == "1"),
        "not inside scripts/isolated (run: scripts/isolated cargo nextest run --profile interop)",
    )
}

/// One of our release binaries (`cargo build --release` first); `INTEROP_BIN_DIR` points elsewhere
/// (e.g. target/debug) when iterating.
pub fn our_bin(name: &str) -> Result<PathBuf, Skip> {
    let dir = std::env::var_os("INTEROP_BIN_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/release"));
    let p = dir.join(name);
    require(
        p.is_file(),
        &format!("{} not built (cargo build --release --bins)", p.display()),
    )?;
    Ok(p)
}

fn probe(cmd: &str, args: &[&str]) -> bool {
    Command::new(cmd)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// `python3` with the `cyclonedds` module, and the peer script.
pub fn cyclone_peer() -> Result<PathBuf, Skip> {
    static OK: OnceLock<bool> = OnceLock::new();
    let ok = *OK.get_or_init(|| probe("python3", &["-c", "import cyclonedds.domain"]));
    require(
        ok,
        "python3 with cyclonedds==11.0.1 (pip install cyclonedds==11.0.1)",
    )?;
    Ok(root().join("tests/peers/cyclone_shape.py"))
}

/// The Fast DDS peer, built on first use by scripts/build-fastdds-peer.sh.
pub fn fastdds_peer() -> Result<PathBuf, Skip> {
    static BUILT: OnceLock<bool> = OnceLock::new();
    let ok = *BUILT.get_or_init(|| {
        Command::new(root().join("scripts/build-fastdds-peer.sh"))
            .stdout(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    });
    let p = root().join("target/peers/fastdds_shape_main");
    require(
        ok && p.is_file(),
        "Fast DDS peer (apt-get install libfastrtps-dev g++; scripts/build-fastdds-peer.sh)",
    )?;
    Ok(p)
}

/// Cyclone's `ddsperf` (Debian cyclonedds-tools).
pub fn ddsperf() -> Result<PathBuf, Skip> {
    let p = PathBuf::from("/usr/bin/ddsperf");
    let found = if p.is_file() {
        Some(p)
    } else {
        which("ddsperf")
    };
    require(
        found.is_some(),
        "ddsperf (apt-get install cyclonedds-tools)",
    )?;
    Ok(found.expect("checked"))
}

/// `tshark`.
pub fn tshark() -> Result<PathBuf, Skip> {
    let found = which("tshark");
    require(found.is_some(), "tshark (apt-get install tshark)")?;
    Ok(found.expect("checked"))
}

/// `tmux`, for the terminal UI test. Skipped (with a message) when absent, in CI too: the UI is checked
/// where tmux is installed.
pub fn tmux() -> Result<PathBuf, Skip> {
    which("tmux").ok_or_else(|| {
        eprintln!("SKIP: tmux not installed (apt-get install tmux)");
        Skip
    })
}

fn which(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH")?
        .to_str()?
        .split(':')
        .map(|d| Path::new(d).join(name))
        .find(|p| p.is_file())
}

#[derive(Default)]
struct Output {
    lines: Vec<String>,
    closed: bool,
}

/// A running program whose stdout (and stderr) lines are collected.
pub struct Proc {
    pub name: String,
    child: Child,
    out: Arc<(Mutex<Output>, Condvar)>,
    status: Option<ExitStatus>,
}

impl Proc {
    /// Spawns `cmd` with piped output. `name` labels the dump on failure.
    pub fn spawn(name: &str, mut cmd: Command) -> Proc {
        cmd.stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let mut child = cmd
            .spawn()
            .unwrap_or_else(|e| panic!("spawning {name} ({cmd:?}): {e}"));
        let out = Arc::new((Mutex::new(Output::default()), Condvar::new()));
        let stdout = child.stdout.take().expect("piped stdout");
        let stderr = child.stderr.take().expect("piped stderr");
        let o1 = out.clone();
        thread::spawn(move || pump(stdout, o1, ""));
        let o2 = out.clone();
        thread::spawn(move || pump(stderr, o2, "stderr: "));
        Proc {
            name: name.to_string(),
            child,
            out,
            status: None,
        }
    }

    /// Waits until a line satisfies `pred`; returns it, or `None` at the deadline or when the output ends.
    pub fn wait_line(&self, timeout: Duration, pred: impl Fn(&str) -> bool) -> Option<String> {
        self.wait_lines(timeout, 1, pred).and_then(|mut v| v.pop())
    }

    /// Waits until `n` lines satisfy `pred`; returns them.
    pub fn wait_lines(
        &self,
        timeout: Duration,
        n: usize,
        pred: impl Fn(&str) -> bool,
    ) -> Option<Vec<String>> {
        let deadline = Instant::now() + timeout;
        let (lock, cv) = &*self.out;
        let mut g = lock.lock().expect("output lock");
        loop {
            let found: Vec<String> = g.lines.iter().filter(|l| pred(l)).cloned().collect();
            if found.len() >= n {
                return Some(found);
            }
            let now = Instant::now();
            if now >= deadline || g.closed {
                return None;
            }
            g = cv.wait_timeout(g, deadline - now).expect("output lock").0;
        }
    }

    /// All lines so far.
    pub fn lines(&self) -> Vec<String> {
        self.out.0.lock().expect("output lock").lines.clone()
    }

    /// Lines so far satisfying `pred`.
    pub fn grep(&self, pred: impl Fn(&str) -> bool) -> Vec<String> {
        self.lines().into_iter().filter(|l| pred(l)).collect()
    }

    /// Waits for the process to exit by itself.
    pub fn wait_exit(&mut self, timeout: Duration) -> Option<ExitStatus> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(s) = self.status {
                return Some(s);
            }
            if let Ok(Some(s)) = self.child.try_wait() {
                self.status = Some(s);
                // Let the pump threads drain what is left.
                let _ = self.wait_closed(Duration::from_secs(2));
                return Some(s);
            }
            if Instant::now() >= deadline {
                return None;
            }
            thread::sleep(Duration::from_millis(20));
        }
    }

    fn wait_closed(&self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        let (lock, cv) = &*self.out;
        let mut g = lock.lock().expect("output lock");
        while !g.closed {
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            g = cv.wait_timeout(g, deadline - now).expect("output lock").0;
        }
        true
    }

    /// SIGINT (the programs' clean stop), then waits up to `timeout` for the exit.
    pub fn interrupt(&mut self, timeout: Duration) -> Option<ExitStatus> {
        if self.status.is_none() {
            let _ = Command::new("kill")
                .arg("-INT")
                .arg(self.child.id().to_string())
                .status();
        }
        self.wait_exit(timeout)
    }

    /// The output, for assertion messages.
    pub fn dump(&self) -> String {
        let lines = self.lines();
        let skip = lines.len().saturating_sub(60);
        let mut s = format!("---- {} ({} lines, last 60) ----\n", self.name, lines.len());
        for l in &lines[skip..] {
            s.push_str(l);
            s.push('\n');
        }
        s
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        if self.status.is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

fn pump(r: impl std::io::Read, out: Arc<(Mutex<Output>, Condvar)>, tag: &str) {
    let mut reader = BufReader::new(r);
    let mut buf = Vec::new();
    loop {
        buf.clear();
        match reader.read_until(b'\n', &mut buf) {
            Ok(0) | Err(_) => break,
            Ok(_) => {
                let line = String::from_utf8_lossy(&buf)
                    .trim_end_matches(['\n', '\r'])
                    .to_string();
                let (lock, cv) = &*out;
                lock.lock()
                    .expect("output lock")
                    .lines
                    .push(format!("{tag}{line}"));
                cv.notify_all();
            }
        }
    }
    let (lock, cv) = &*out;
    // Two pumps (stdout, stderr): "closed" once stdout ended is enough for line waits.
    if tag.is_empty() {
        lock.lock().expect("output lock").closed = true;
    }
    cv.notify_all();
}

/// Dumps the given processes' output into one string for an assertion message.
pub fn dumps(procs: &[&Proc]) -> String {
    procs.iter().map(|p| p.dump()).collect::<Vec<_>>().join("")
}

/// Asserts with the processes' output attached.
#[macro_export]
macro_rules! check {
    ($cond:expr, $procs:expr, $($msg:tt)+) => {
        if !$cond {
            panic!("{}\n{}", format!($($msg)+), $crate::interop::harness::dumps($procs));
        }
    };
}
