//! The terminal window of `shapes` (ratatui): the bouncing shapes of every writer we receive, ours and other
//! implementations', a side panel with topics, colours, rates and matched endpoints, and keys to publish,
//! subscribe, pause and quit. [`app`] holds the state, [`input`] maps keys, [`draw`] renders, [`board`]
//! remembers the received shapes; the DDS work is `crate::shapes_demo::session`, shared with the batch mode.

pub mod app;
pub mod board;
pub mod draw;
pub mod input;

use std::fmt;
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
    let result = event_loop(&mut terminal, &mut app, a, start);
    ratatui::restore();
    result?;
    app.session.flush();
    let written = (!app.session.publications().is_empty()).then(|| WrittenSummary {
        written: app.session.written(),
        shapes: app.session.publications().len(),
        rate_hz: app.session.rate_hz(),
    });
    let subscribed = !app.session.subscribed_topics().is_empty();
    for line in app.tally.summary(start.elapsed(), written, subscribed) {
        println!("{line}");
    }
    Ok(u8::from(subscribed && app.tally.samples == 0))
}

fn event_loop(
    terminal: &mut DefaultTerminal,
    app: &mut App,
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
            if !event::poll(wait)? {
                break;
            }
            if let Event::Key(key) = event::read()? {
                if let Some(action) = input::action(key) {
                    app.apply(action)?;
                }
            }
        }
        app.step(Instant::now())?;
    }
}
