//! What the window shows of the received shapes: the last position of every (topic, colour, writer), a short
//! trail, the arrival rate, and which implementation wrote it.

use std::collections::{BTreeMap, VecDeque};
use std::time::{Duration, Instant};

use crate::shapes_demo::origin::WriterId;
use crate::shapes_demo::session::{Received, ReceivedEvent};

/// Positions kept for the trail behind a shape.
const TRAIL: usize = 6;
/// Window over which the sample rate is measured.
const RATE_WINDOW: Duration = Duration::from_secs(2);
/// A shape not heard from for this long leaves the board.
const STALE: Duration = Duration::from_secs(5);

/// One shape instance as a writer publishes it.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct ShapeKey {
    /// Topic (Square, Circle, Triangle, ...).
    pub topic: String,
    /// Colour (the instance key).
    pub color: String,
    /// The writer.
    pub writer: WriterId,
}

/// The latest state of a received shape.
#[derive(Debug, Clone)]
pub struct Seen {
    /// Centre, in world coordinates.
    pub x: i32,
    /// Centre, in world coordinates.
    pub y: i32,
    /// Size in world units.
    pub size: i32,
    /// Earlier centres, oldest first.
    pub trail: VecDeque<(i32, i32)>,
    /// Whether this process wrote it.
    pub ours: bool,
    arrivals: VecDeque<Instant>,
}

impl Seen {
    /// Samples per second over the last two seconds.
    pub fn rate(&self, now: Instant) -> f64 {
        let n = self
            .arrivals
            .iter()
            .filter(|t| now.duration_since(**t) <= RATE_WINDOW)
            .count();
        n as f64 / RATE_WINDOW.as_secs_f64()
    }
}

/// Every shape received and still alive.
#[derive(Debug, Default)]
pub struct Board {
    shapes: BTreeMap<ShapeKey, Seen>,
}

impl Board {
    /// Applies what a reader delivered; `ours` tells whether our own participant wrote it.
    pub fn apply(&mut self, r: &Received, ours: bool, now: Instant) {
        match &r.event {
            ReceivedEvent::Data { shape, .. } => {
                let key = ShapeKey {
                    topic: r.topic.clone(),
                    color: shape.color.clone(),
                    writer: r.writer,
                };
                let seen = self.shapes.entry(key).or_insert_with(|| Seen {
                    x: shape.x,
                    y: shape.y,
                    size: shape.shapesize,
                    trail: VecDeque::new(),
                    ours,
                    arrivals: VecDeque::new(),
                });
                if seen.trail.len() == TRAIL {
                    seen.trail.pop_front();
                }
                seen.trail.push_back((seen.x, seen.y));
                (seen.x, seen.y, seen.size) = (shape.x, shape.y, shape.shapesize);
                seen.arrivals.push_back(now);
                while seen
                    .arrivals
                    .front()
                    .is_some_and(|t| now.duration_since(*t) > RATE_WINDOW)
                {
                    seen.arrivals.pop_front();
                }
            }
            ReceivedEvent::Gone { color } => {
                self.shapes.retain(|k, _| {
                    !(k.topic == r.topic && k.color == *color && k.writer == r.writer)
                });
            }
        }
    }

    /// Forgets shapes not heard from for five seconds.
    pub fn expire(&mut self, now: Instant) {
        self.shapes.retain(|_, s| {
            s.arrivals
                .back()
                .is_some_and(|t| now.duration_since(*t) < STALE)
        });
    }

    /// The shapes, ordered by topic, colour and writer.
    pub fn shapes(&self) -> impl Iterator<Item = (&ShapeKey, &Seen)> {
        self.shapes.iter()
    }

    /// The participants heard from (a writer's prefix names its participant), with the number of shapes
    /// each one publishes and whether it is ours.
    pub fn participants(&self) -> BTreeMap<WriterId, (usize, bool)> {
        let mut out = BTreeMap::new();
        for (k, s) in &self.shapes {
            let mut participant = k.writer;
            participant.0[12..].fill(0);
            out.entry(participant).or_insert((0, s.ours)).0 += 1;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topic_types::ShapeType;

    fn data(color: &str, x: i32) -> Received {
        Received {
            topic: "Square".into(),
            writer: WriterId([1; 16]),
            event: ReceivedEvent::Data {
                shape: ShapeType {
                    color: color.into(),
                    x,
                    y: 5,
                    shapesize: 30,
                    ..Default::default()
                },
                latency: Duration::ZERO,
            },
        }
    }

    #[test]
    fn positions_trail_rate_and_removal() {
        let mut b = Board::default();
        let t0 = Instant::now();
        for i in 0..10 {
            b.apply(
                &data("RED", i),
                true,
                t0 + Duration::from_millis(100 * i as u64),
            );
        }
        let (k, s) = b.shapes().next().expect("one shape");
        assert_eq!((k.color.as_str(), s.x, s.trail.len()), ("RED", 9, TRAIL));
        assert_eq!(s.trail.back(), Some(&(8, 5)));
        assert!((s.rate(t0 + Duration::from_millis(900)) - 5.0).abs() < 1e-9);
        assert_eq!(b.participants().len(), 1);
        let gone = Received {
            event: ReceivedEvent::Gone {
                color: "RED".into(),
            },
            ..data("RED", 0)
        };
        b.apply(&gone, true, t0);
        assert_eq!(b.shapes().count(), 0);
        b.apply(&data("BLUE", 1), false, t0);
        b.expire(t0 + STALE);
        assert_eq!(b.shapes().count(), 0);
    }
}
