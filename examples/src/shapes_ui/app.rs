//! The window's state: the shared DDS session, the board of received shapes, the selected topic and colour,
//! and what the keys do to them.

use std::time::Instant;

use dds_runtime::prelude::DdsResult;

use super::board::Board;
use super::input::Action;
use crate::shapes_demo::session::{ReceivedEvent, Session};
use crate::shapes_demo::tally::Tally;

/// The topics of the OMG shapes demo.
pub const TOPICS: [&str; 3] = ["Square", "Circle", "Triangle"];
/// The colours of the OMG shapes demo.
pub const COLORS: [&str; 8] = [
    "PURPLE", "BLUE", "RED", "GREEN", "YELLOW", "CYAN", "MAGENTA", "ORANGE",
];

/// Everything the window shows and changes.
pub struct App {
    /// The DDS entities and our published shapes.
    pub session: Session,
    /// Received shapes.
    pub board: Board,
    /// Received samples, for the summary printed at the end.
    pub tally: Tally,
    /// Topics that can be selected: the demo's three and the one from the command line.
    pub topics: Vec<String>,
    /// Index of the selected topic in `topics`.
    pub topic: usize,
    /// Index of the selected colour in [`COLORS`].
    pub color: usize,
    /// Our shapes stand still and the picture is frozen.
    pub paused: bool,
    /// The last thing that happened, shown at the bottom.
    pub status: String,
    /// The user asked to leave.
    pub quit: bool,
    /// DDS domain, shown in the title.
    pub domain: u32,
}

impl App {
    /// The window on `session`, with `topic` (from the command line) selected.
    pub fn new(session: Session, topic: &str, domain: u32) -> Self {
        let mut topics: Vec<String> = TOPICS.iter().map(|t| t.to_string()).collect();
        if !topics.iter().any(|t| t == topic) {
            topics.push(topic.to_string());
        }
        let topic = topics.iter().position(|t| t == topic).unwrap_or(0);
        let mut app = App {
            session,
            board: Board::default(),
            tally: Tally::default(),
            topics,
            topic,
            color: 0,
            paused: false,
            status: "press p to publish a shape".into(),
            quit: false,
            domain,
        };
        app.color = app.unused_color(0);
        app
    }

    /// The selected topic.
    pub fn selected_topic(&self) -> &str {
        &self.topics[self.topic]
    }

    /// The selected colour.
    pub fn selected_color(&self) -> &'static str {
        COLORS[self.color]
    }

    /// Carries out a key's action.
    pub fn apply(&mut self, action: Action) -> DdsResult<()> {
        let n = self.topics.len();
        match action {
            Action::Quit => self.quit = true,
            Action::NextTopic => self.topic = (self.topic + 1) % n,
            Action::PrevTopic => self.topic = (self.topic + n - 1) % n,
            Action::NextColor => self.color = (self.color + 1) % COLORS.len(),
            Action::PrevColor => self.color = (self.color + COLORS.len() - 1) % COLORS.len(),
            Action::Pause => {
                self.paused = !self.paused;
                self.status = if self.paused { "paused" } else { "running" }.into();
            }
            Action::Subscribe => {
                let topic = self.selected_topic().to_string();
                self.status = if self.session.is_subscribed(&topic) {
                    format!("already subscribed to {topic}")
                } else {
                    self.session.subscribe(&topic)?;
                    format!("subscribed to {topic}")
                };
            }
            Action::Publish => {
                let (topic, color) = (self.selected_topic().to_string(), self.selected_color());
                let index = self.session.publications().len();
                self.session.publish(&topic, color, index)?;
                self.status = format!("publishing {color} on {topic}");
                self.color = self.unused_color(self.color);
            }
        }
        Ok(())
    }

    /// Writes what is due, takes what arrived and updates the board (frozen while paused).
    pub fn step(&mut self, now: Instant) -> DdsResult<()> {
        if self.paused {
            self.session.hold(now);
        } else {
            self.session.tick(now)?;
        }
        for r in self.session.receive()? {
            if let ReceivedEvent::Data { shape, latency } = &r.event {
                self.tally.record(&shape.color, *latency);
            }
            if !self.paused {
                let ours = self.session.is_ours(&r.writer);
                self.board.apply(&r, ours, now);
            }
        }
        if !self.paused {
            self.board.expire(now);
        }
        Ok(())
    }

    /// The first colour from `from` on that we do not publish on the selected topic yet.
    fn unused_color(&self, from: usize) -> usize {
        let topic = self.selected_topic();
        (0..COLORS.len())
            .map(|i| (from + i) % COLORS.len())
            .find(|&i| {
                !self
                    .session
                    .publications()
                    .iter()
                    .any(|p| p.topic == topic && p.shape.color == COLORS[i])
            })
            .unwrap_or(from)
    }
}
