//! The terminal window of `shapes` (ratatui): the bouncing shapes of every writer we receive, ours and other
//! implementations', a side panel with topics, colours, rates and matched endpoints, and keys to publish,
//! subscribe, pause and quit. [`app`] holds the state, [`input`] maps keys, [`draw`] renders, [`board`]
//! remembers the received shapes; the DDS work is `crate::shapes_demo::session`, shared with the batch mode.

pub mod app;
pub mod board;
pub mod draw;
pub mod input;

use std::fmt;
use std::io::{self, Write};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use dds_runtime::prelude::DdsError;
use ratatui::crossterm::event::{self, Event};
use ratatui::DefaultTerminal;

use crate::shapes_demo::args::ShapesArgs;
use crate::shapes_demo::session::Session;
use crate::shapes_demo::tally::WrittenSummary;
use crate::shutdown;
use app::App;

/// Time between two frames.
const FRAME: Duration = Duration::from_millis(50);

/// Why the window stopped.
#[derive(Debug)]
pub enum UiError {
    /// The terminal could not be set up, read or drawn.
    Terminal(std::io::Error),
    /// A DDS operation failed.
    Dds(DdsError),
}

impl fmt::Display for UiError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            UiError::Terminal(e) => write!(f, "terminal: {e}"),
            UiError::Dds(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for UiError {}

impl From<std::io::Error> for UiError {
    fn from(e: std::io::Error) -> Self {
        UiError::Terminal(e)
    }
}

impl From<DdsError> for UiError {
    fn from(e: DdsError) -> Self {
        UiError::Dds(e)
    }
}

/// Runs the window until q (or `--duration`, `--count`, SIGTERM), then prints the batch mode's summary on
/// the restored terminal; returns the exit code (1 when subscribing and nothing was received).
pub fn run(session: Session, a: &ShapesArgs) -> Result<u8, UiError> {
    let mut app = App::new(session, &a.topic, a.domain);
    let start = Instant::now();
    let mut terminal = ratatui::try_init()?;
    let result =
        spawn_input().and_then(|events| event_loop(&mut terminal, &mut app, &events, a, start));
    ratatui::restore();
    result?;
    app.session.flush();
    let written = (!app.session.publications().is_empty()).then(|| WrittenSummary {
        written: app.session.written(),
        shapes: app.session.publications().len(),
        rate_hz: app.session.rate_hz(),
    });
    let subscribed = !app.session.subscribed_topics().is_empty();
    // The terminal may be gone (hung up): the summary is then lost, not a reason to fail.
    let mut out = io::stdout().lock();
    for line in app.tally.summary(start.elapsed(), written, subscribed) {
        let _ = writeln!(out, "{line}");
    }
    Ok(u8::from(subscribed && app.tally.samples == 0))
}

/// Reads terminal events on a thread of their own. When the terminal hangs up, crossterm's poll can spin
/// without returning; the frame loop then still runs, sees SIGHUP/SIGTERM through [`shutdown`], and leaves.
fn spawn_input() -> Result<Receiver<io::Result<Event>>, UiError> {
    let (tx, rx) = mpsc::channel();
    std::thread::Builder::new()
        .name("shapes-input".into())
        .spawn(move || loop {
            let ev = event::read();
            let failed = ev.is_err();
            if tx.send(ev).is_err() || failed {
                break;
            }
        })?;
    Ok(rx)
}

fn event_loop(
    terminal: &mut DefaultTerminal,
    app: &mut App,
    events: &Receiver<io::Result<Event>>,
    a: &ShapesArgs,
    start: Instant,
) -> Result<(), UiError> {
    loop {
        terminal.draw(|f| draw::draw(f, app))?;
        let done = app.quit
            || shutdown::requested()
            || a.duration.is_some_and(|d| start.elapsed() >= d)
            || a.count.is_some_and(|n| app.tally.samples >= n);
        if done {
            return Ok(());
        }
        let frame_end = Instant::now() + FRAME;
        while let Some(wait) = frame_end.checked_duration_since(Instant::now()) {
            let ev = match events.recv_timeout(wait) {
                Ok(ev) => ev?,
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => return Ok(()),
            };
            if let Event::Key(key) = ev {
                if let Some(action) = input::action(key) {
                    app.apply(action)?;
                }
            }
        }
        app.step(Instant::now())?;
    }
}
