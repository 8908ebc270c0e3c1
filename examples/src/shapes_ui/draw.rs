//! Drawing the window: the world of bouncing shapes on the left, the side panel (selection, topics, our
//! shapes, received shapes, matched writers) on the right, the keys at the bottom.

use std::time::Instant;

use ratatui::buffer::Buffer;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style, Stylize};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Paragraph, Widget};
use ratatui::Frame;

use super::app::App;
use super::board::Board;
use super::input::LEGEND;
use crate::shape_motion::{WORLD_HEIGHT, WORLD_WIDTH};

/// Width of the side panel.
const PANEL_WIDTH: u16 = 42;

/// Draws the whole window.
pub fn draw(frame: &mut Frame, app: &App) {
    let [main, footer] =
        Layout::vertical([Constraint::Min(3), Constraint::Length(1)]).areas(frame.area());
    let [world, panel] =
        Layout::horizontal([Constraint::Min(20), Constraint::Length(PANEL_WIDTH)]).areas(main);
    let title = format!(
        " shapes · domain {}{} ",
        app.domain,
        if app.paused { " · PAUSED" } else { "" }
    );
    frame.render_widget(
        World {
            board: &app.board,
            title,
        },
        world,
    );
    frame.render_widget(
        Paragraph::new(panel_lines(app, Instant::now())).block(Block::bordered().title(" dds-rs ")),
        panel,
    );
    let footer_text = Line::from(vec![
        Span::styled(format!(" {LEGEND} "), Style::new().reversed()),
        Span::raw(format!("  {}", app.status)),
    ]);
    frame.render_widget(Paragraph::new(footer_text), footer);
}

/// The terminal colour of a shapes-demo colour name.
pub fn color_of(name: &str) -> Color {
    match name {
        "PURPLE" => Color::Rgb(160, 32, 240),
        "BLUE" => Color::Blue,
        "RED" => Color::Red,
        "GREEN" => Color::Green,
        "YELLOW" => Color::Yellow,
        "CYAN" => Color::Cyan,
        "MAGENTA" => Color::Magenta,
        "ORANGE" => Color::Rgb(255, 165, 0),
        "BLACK" => Color::DarkGray,
        _ => Color::White,
    }
}

/// The glyph a topic's shapes are drawn with.
pub fn glyph_of(topic: &str) -> char {
    match topic {
        "Circle" => '●',
        "Triangle" => '▲',
        _ => '■',
    }
}

/// The world of shapes: every received shape at its position scaled from the 240 x 270 world, drawn with
/// its glyph over its size, with a dotted trail.
struct World<'a> {
    board: &'a Board,
    title: String,
}

impl Widget for World<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let block = Block::bordered().title(self.title.clone());
        let inner = block.inner(area);
        block.render(area, buf);
        if inner.width == 0 || inner.height == 0 {
            return;
        }
        let scale = Scale(inner);
        for (key, seen) in self.board.shapes() {
            let color = color_of(&key.color);
            for &(x, y) in &seen.trail {
                let (c, r) = scale.cell(x, y);
                if let Some(cell) = buf.cell_mut((c, r)) {
                    cell.set_char('·').set_fg(color);
                }
            }
            let style = Style::new().fg(color).add_modifier(Modifier::BOLD);
            for (c, r) in footprint(&key.topic, scale, seen.x, seen.y, seen.size) {
                if let Some(cell) = buf.cell_mut((c, r)) {
                    cell.set_char(glyph_of(&key.topic)).set_style(style);
                }
            }
        }
    }
}

/// Maps world coordinates to the cells of an area.
#[derive(Debug, Clone, Copy)]
struct Scale(Rect);

impl Scale {
    fn cell(&self, x: i32, y: i32) -> (u16, u16) {
        let r = self.0;
        let map = |v: i32, max: i32, cells: u16| -> u16 {
            let v = v.clamp(0, max) as u32;
            (v * u32::from(cells.saturating_sub(1)) / max as u32) as u16
        };
        (
            r.x + map(x, WORLD_WIDTH, r.width),
            r.y + map(y, WORLD_HEIGHT, r.height),
        )
    }

    /// A world length in cells, horizontally and vertically (at least one).
    fn extent(&self, size: i32) -> (i32, i32) {
        let size = size.clamp(0, WORLD_WIDTH);
        let w = size * i32::from(self.0.width) / WORLD_WIDTH;
        let h = size * i32::from(self.0.height) / WORLD_HEIGHT;
        (w.max(1), h.max(1))
    }
}

/// The cells a shape covers: a filled square, circle or triangle around its centre, inside the area.
fn footprint(topic: &str, scale: Scale, x: i32, y: i32, size: i32) -> Vec<(u16, u16)> {
    let (cx, cy) = scale.cell(x, y);
    let (w, h) = scale.extent(size);
    let area = scale.0;
    let mut out = Vec::new();
    for j in 0..h {
        for i in 0..w {
            // Cell centre relative to the shape's centre, in [-1, 1].
            let dx = (f64::from(i) + 0.5) / f64::from(w) * 2.0 - 1.0;
            let dy = (f64::from(j) + 0.5) / f64::from(h) * 2.0 - 1.0;
            let inside = match topic {
                "Circle" => dx * dx + dy * dy <= 1.1,
                "Triangle" => dx.abs() <= (dy + 1.0) / 2.0 + 0.5 / f64::from(w),
                _ => true,
            };
            let c = i32::from(cx) - w / 2 + i;
            let r = i32::from(cy) - h / 2 + j;
            let within = (i32::from(area.x)..i32::from(area.right())).contains(&c)
                && (i32::from(area.y)..i32::from(area.bottom())).contains(&r);
            if inside && within {
                out.push((c as u16, r as u16));
            }
        }
    }
    out
}

/// The side panel's lines.
fn panel_lines(app: &App, now: Instant) -> Vec<Line<'static>> {
    let heading = |s: &str| {
        Line::from(Span::styled(
            s.to_string(),
            Style::new().bold().underlined(),
        ))
    };
    let swatch = |topic: &str, color: &str| {
        Span::styled(
            format!("{} ", glyph_of(topic)),
            Style::new().fg(color_of(color)).bold(),
        )
    };
    let mut lines = vec![
        Line::from(vec![
            Span::raw("next: "),
            swatch(app.selected_topic(), app.selected_color()),
            Span::raw(format!("{} {}", app.selected_color(), app.selected_topic())),
        ]),
        heading("Topics: matched endpoints"),
    ];
    for t in app.session.topic_status() {
        let sub = t.matched_writers.map_or("-".to_string(), |n| n.to_string());
        let publ = t.matched_readers.map_or("-".to_string(), |n| n.to_string());
        lines.push(Line::raw(format!(
            "{:<9} writers {sub:>2}  readers {publ:>2}",
            t.name
        )));
    }
    lines.push(heading("Publishing"));
    for p in app.session.publications() {
        lines.push(Line::from(vec![
            swatch(&p.topic, &p.shape.color),
            Span::raw(format!(
                "{:<8} {:<8} {:>5.1}/s",
                p.shape.color,
                p.topic,
                if app.paused {
                    0.0
                } else {
                    app.session.rate_hz()
                }
            )),
        ]));
    }
    lines.push(heading("Received"));
    for (k, s) in app.board.shapes() {
        let from = if s.ours { "ours" } else { k.writer.vendor() };
        lines.push(Line::from(vec![
            swatch(&k.topic, &k.color),
            Span::raw(format!(
                "{:<8} {:<8} {:>5.1}/s {from}",
                k.color,
                k.topic,
                s.rate(now)
            )),
        ]));
    }
    lines.push(heading("Participants heard"));
    for (p, (n, ours)) in app.board.participants() {
        let who = if ours { "ours" } else { p.vendor() };
        // Vendor, the first two groups of the GUID prefix, shapes heard from it.
        lines.push(Line::raw(format!("{who:<12}{:.17} {n:>3}", p.to_string())));
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes_demo::origin::WriterId;
    use crate::shapes_demo::session::{Received, ReceivedEvent, Session, SessionConfig};
    use crate::topic_types::ShapeType;
    use ratatui::backend::TestBackend;
    use ratatui::Terminal;
    use std::time::Duration;

    #[test]
    fn window_shows_received_shapes_in_world_and_panel() {
        // No DDS entity exists until something is published or subscribed: this test opens no socket.
        let session = Session::new(SessionConfig {
            domain: 0,
            xcdr2: false,
            rate_hz: 10.0,
        });
        let mut app = App::new(session, "Square", 0);
        let mut cyclone = [0u8; 16];
        cyclone[..2].copy_from_slice(&[0x01, 0x10]);
        let received = Received {
            topic: "Circle".into(),
            writer: WriterId(cyclone),
            event: ReceivedEvent::Data {
                shape: ShapeType {
                    color: "GREEN".into(),
                    x: 120,
                    y: 135,
                    shapesize: 30,
                    ..Default::default()
                },
                latency: Duration::ZERO,
            },
        };
        app.board.apply(&received, false, Instant::now());
        let mut terminal = Terminal::new(TestBackend::new(100, 30)).expect("test terminal");
        terminal.draw(|f| draw(f, &app)).expect("draws");
        let buf = terminal.backend().buffer().clone();
        let row =
            |y: u16| -> String { (0..100).map(|x| buf[(x, y)].symbol().to_string()).collect() };
        let screen: Vec<String> = (0..30).map(row).collect();
        let world_width = 100 - usize::from(PANEL_WIDTH);
        let circle_cells: Vec<(u16, u16)> = (0..30u16)
            .flat_map(|y| (0..world_width as u16).map(move |x| (x, y)))
            .filter(|&(x, y)| buf[(x, y)].symbol() == "●")
            .collect();
        assert!(!circle_cells.is_empty(), "{}", screen.join("\n"));
        assert!(circle_cells
            .iter()
            .all(|&(x, y)| buf[(x, y)].fg == Color::Green));
        assert!(screen
            .iter()
            .any(|l| l.contains("● GREEN") && l.contains("Cyclone DDS")));
        assert!(screen.iter().any(|l| l.contains("next: ■ PURPLE Square")));
        assert!(screen[29].contains("p publish"));
    }

    #[test]
    fn world_corners_map_to_the_area_corners() {
        let s = Scale(Rect::new(1, 1, 60, 20));
        assert_eq!(s.cell(0, 0), (1, 1));
        assert_eq!(s.cell(WORLD_WIDTH, WORLD_HEIGHT), (60, 20));
        assert_eq!(s.cell(-5, 999), (1, 20));
    }

    #[test]
    fn footprints_have_their_shape() {
        let s = Scale(Rect::new(0, 0, 80, 27));
        let square = footprint("Square", s, 120, 135, 30);
        assert_eq!(square.len(), 10 * 3);
        let triangle = footprint("Triangle", s, 120, 135, 30);
        assert!(triangle.len() < square.len());
        let top_row = triangle.iter().map(|c| c.1).min().expect("cells");
        let top = triangle.iter().filter(|c| c.1 == top_row).count();
        let bottom = triangle.iter().filter(|c| c.1 != top_row).count();
        assert!(top < bottom / 2);
        // Shapes at the edge are cut, never drawn outside.
        assert!(footprint("Circle", s, 0, 0, 30)
            .iter()
            .all(|&(c, r)| c < 80 && r < 27));
    }
}
