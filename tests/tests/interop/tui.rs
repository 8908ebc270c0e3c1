//! The `shapes` window as a person sees it: the release binary runs in a detached tmux session of a fixed
//! size; the test types keys with `send-keys` and reads the screen with `capture-pane`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::thread;
use std::time::{Duration, Instant};

use super::harness::{our_bin, require_netns, tmux, Skip};

/// Columns and rows of the tmux window.
const WIDTH: usize = 110;
const HEIGHT: usize = 32;
/// Columns of the side panel (`shapes_ui::draw::PANEL_WIDTH`).
const PANEL: usize = 42;
const WAIT: Duration = Duration::from_secs(15);

/// A tmux server of our own (its own socket), killed on drop. It is started from this process, so its
/// programs run in the same network namespace.
struct Tmux {
    bin: PathBuf,
    socket: String,
}

impl Tmux {
    fn start(bin: PathBuf, command: &str) -> Tmux {
        let t = Tmux {
            bin,
            socket: format!("dds-tui-{}", std::process::id()),
        };
        let (w, h) = (WIDTH.to_string(), HEIGHT.to_string());
        let out = t.run(&["new-session", "-d", "-s", "ui", "-x", &w, "-y", &h, command]);
        assert!(out.status.success(), "tmux new-session: {out:?}");
        t
    }

    fn run(&self, args: &[&str]) -> Output {
        Command::new(&self.bin)
            .args(["-L", &self.socket, "-f", "/dev/null"])
            .args(args)
            .env_remove("TMUX")
            .output()
            .expect("running tmux")
    }

    fn keys(&self, keys: &[&str]) {
        let mut args = vec!["send-keys", "-t", "ui"];
        args.extend_from_slice(keys);
        assert!(self.run(&args).status.success(), "send-keys {keys:?}");
    }

    fn screen(&self) -> String {
        String::from_utf8_lossy(&self.run(&["capture-pane", "-p", "-t", "ui"]).stdout).into_owned()
    }

    /// Polls the screen until `pred` holds; panics with the last screen at the deadline.
    fn wait_for(&self, what: &str, pred: impl Fn(&Screen) -> bool) -> Screen {
        let deadline = Instant::now() + WAIT;
        loop {
            let s = Screen(self.screen());
            if pred(&s) {
                return s;
            }
            assert!(Instant::now() < deadline, "no {what} on screen:\n{}", s.0);
            thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.run(&["kill-server"]);
    }
}

/// A captured screen.
struct Screen(String);

impl Screen {
    /// The world part of each line (left of the side panel).
    fn world(&self) -> impl Iterator<Item = String> + '_ {
        self.0.lines().map(|l| {
            let chars: Vec<char> = l.chars().collect();
            chars[..chars.len().saturating_sub(PANEL)].iter().collect()
        })
    }

    fn world_has(&self, glyph: char) -> bool {
        self.world().any(|l| l.contains(glyph))
    }

    /// A panel line containing every word of `words`.
    fn panel_has(&self, words: &[&str]) -> bool {
        self.0.lines().any(|l| {
            let chars: Vec<char> = l.chars().collect();
            let panel: String = chars[chars.len().saturating_sub(PANEL)..].iter().collect();
            words.iter().all(|w| panel.contains(w))
        })
    }
}

#[test]
fn shapes_window_draws_shapes_and_publishes_on_key_press() {
    let _ = window();
}

fn window() -> Result<(), Skip> {
    require_netns()?;
    let tmux_bin = tmux()?;
    let shapes = our_bin("shapes")?;
    let command = format!(
        "{} --domain 141 --rate 20; echo shapes exited $?; sleep 60",
        shell_word(&shapes)
    );
    let t = Tmux::start(tmux_bin, &command);

    // Our two default squares are drawn and listed as received from ourselves.
    t.wait_for("squares", |s| {
        s.world_has('■')
            && s.panel_has(&["■ BLUE", "Square", "/s", "ours"])
            && s.panel_has(&["■ RED", "Square", "ours"])
    });

    // t selects Circle, s subscribes to it, p publishes a PURPLE circle: a new publisher, matched and drawn.
    t.keys(&["t", "s", "p"]);
    t.wait_for("the new circle", |s| {
        s.panel_has(&["● PURPLE", "Circle", "/s", "ours"])
            && s.panel_has(&["Circle", "writers  1", "readers  1"])
            && s.world_has('●')
    });

    // Space pauses (title), space again resumes.
    t.keys(&["Space"]);
    t.wait_for("the pause", |s| s.0.contains("PAUSED"));
    t.keys(&["Space"]);
    t.wait_for("the resumption", |s| !s.0.contains("PAUSED"));

    // q leaves the window; the summary of the batch mode follows on the restored terminal.
    t.keys(&["q"]);
    let s = t.wait_for("the summary", |s| s.0.contains("shapes exited"));
    assert!(s.0.contains("shapes exited 0"), "{}", s.0);
    let received =
        s.0.lines()
            .find(|l| l.starts_with("received ") && l.contains(" samples ["))
            .unwrap_or_else(|| panic!("no summary:\n{}", s.0));
    for color in ["BLUE", "PURPLE", "RED"] {
        assert!(received.contains(&format!("{color}: ")), "{received}");
    }
    Ok(())
}

#[test]
fn shapes_window_leaves_when_its_terminal_hangs_up() {
    let _ = hangup();
}

/// The terminal goes away under the window (the tmux server is killed): the process gets SIGHUP and must leave
/// within a few seconds instead of lingering (crossterm's input poll can spin on a hung-up terminal).
fn hangup() -> Result<(), Skip> {
    require_netns()?;
    let tmux_bin = tmux()?;
    let shapes = our_bin("shapes")?;
    let t = Tmux::start(
        tmux_bin,
        &format!("exec {} --domain 143 --rate 20", shell_word(&shapes)),
    );
    t.wait_for("squares", |s| s.world_has('■'));
    let pid = String::from_utf8_lossy(
        &t.run(&["list-panes", "-t", "ui", "-F", "#{pane_pid}"])
            .stdout,
    )
    .trim()
    .to_string();
    assert!(pid.parse::<u32>().is_ok(), "pane pid {pid:?}");
    let _ = t.run(&["kill-server"]);
    let proc_dir = PathBuf::from(format!("/proc/{pid}"));
    let deadline = Instant::now() + Duration::from_secs(5);
    while alive(&proc_dir) && Instant::now() < deadline {
        thread::sleep(Duration::from_millis(100));
    }
    let lingering = alive(&proc_dir);
    if lingering {
        let _ = Command::new("kill").args(["-9", &pid]).status();
    }
    assert!(
        !lingering,
        "shapes (pid {pid}) still ran 5 s after its terminal hung up"
    );
    Ok(())
}

/// Whether the process of `/proc/<pid>` exists and is not a zombie.
fn alive(proc_dir: &Path) -> bool {
    std::fs::read_to_string(proc_dir.join("stat"))
        .map(|st| {
            !st.rsplit(')')
                .next()
                .unwrap_or("")
                .trim_start()
                .starts_with('Z')
        })
        .unwrap_or(false)
}

/// `p` quoted for the shell tmux runs the command with.
fn shell_word(p: &Path) -> String {
    format!("'{}'", p.display().to_string().replace('\'', r"'\''"))
}
