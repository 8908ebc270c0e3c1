//! Keys of the window and what they do.

use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyEventKind, KeyModifiers};

/// What a key asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Leave (q, Esc, Ctrl-C).
    Quit,
    /// Publish a new shape of the selected topic and colour (p, Enter).
    Publish,
    /// Select the next topic (t, Tab).
    NextTopic,
    /// Select the previous topic (T, Shift-Tab).
    PrevTopic,
    /// Select the next colour (c).
    NextColor,
    /// Select the previous colour (C).
    PrevColor,
    /// Subscribe to the selected topic (s).
    Subscribe,
    /// Stop or resume our shapes and the picture (space).
    Pause,
}

/// The key legend shown at the bottom of the window.
pub const LEGEND: &str = "p publish  t topic  c colour  s subscribe  space pause  q quit";

/// The action of a key press; releases and unknown keys do nothing.
pub fn action(key: KeyEvent) -> Option<Action> {
    if key.kind == KeyEventKind::Release {
        return None;
    }
    Some(match key.code {
        KeyCode::Char('c') if key.modifiers.contains(KeyModifiers::CONTROL) => Action::Quit,
        KeyCode::Char('q') | KeyCode::Esc => Action::Quit,
        KeyCode::Char('p') | KeyCode::Enter => Action::Publish,
        KeyCode::Char('t') | KeyCode::Tab => Action::NextTopic,
        KeyCode::Char('T') | KeyCode::BackTab => Action::PrevTopic,
        KeyCode::Char('c') => Action::NextColor,
        KeyCode::Char('C') => Action::PrevColor,
        KeyCode::Char('s') => Action::Subscribe,
        KeyCode::Char(' ') => Action::Pause,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys() {
        let k = |c| KeyEvent::new(KeyCode::Char(c), KeyModifiers::NONE);
        assert_eq!(action(k('p')), Some(Action::Publish));
        assert_eq!(action(k('q')), Some(Action::Quit));
        assert_eq!(action(k('c')), Some(Action::NextColor));
        assert_eq!(
            action(KeyEvent::new(KeyCode::Char('c'), KeyModifiers::CONTROL)),
            Some(Action::Quit)
        );
        assert_eq!(action(k('z')), None);
    }
}
