//! How shapes move: the OMG suite's `moveShape`, bouncing inside its 240 x 270 drawing area. `shape_main` and
//! the `shapes` demo both use it.

use crate::topic_types::ShapeType;

/// Width of the shapes world (x runs from 0 to this, inclusive).
pub const WORLD_WIDTH: i32 = 240;
/// Height of the shapes world (y runs from 0 to this, inclusive; 0 is the top).
pub const WORLD_HEIGHT: i32 = 270;

/// A velocity in world units per write.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Motion {
    /// Horizontal step.
    pub dx: i32,
    /// Vertical step.
    pub dy: i32,
}

impl Motion {
    /// Moves `s` one step, reflecting off the edges of the world (position clamped, velocity negated).
    pub fn step(&mut self, s: &mut ShapeType) {
        s.x += self.dx;
        s.y += self.dy;
        if !(0..=WORLD_WIDTH).contains(&s.x) {
            s.x = s.x.clamp(0, WORLD_WIDTH);
            self.dx = -self.dx;
        }
        if !(0..=WORLD_HEIGHT).contains(&s.y) {
            s.y = s.y.clamp(0, WORLD_HEIGHT);
            self.dy = -self.dy;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounces_off_every_edge() {
        let mut s = ShapeType {
            x: 238,
            y: 2,
            ..Default::default()
        };
        let mut m = Motion { dx: 5, dy: -4 };
        m.step(&mut s);
        assert_eq!((s.x, s.y), (WORLD_WIDTH, 0));
        assert_eq!(m, Motion { dx: -5, dy: 4 });
        m.step(&mut s);
        assert_eq!((s.x, s.y), (235, 4));
    }
}
