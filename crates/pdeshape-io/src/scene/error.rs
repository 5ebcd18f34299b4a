//! Scene errors that name the place (file, line, column, key) and the cause.

use std::fmt;
use std::ops::Range;

/// An error in a scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// The file (or a label such as `<stdin>`).
    pub file: String,
    /// 1-based line, when the place is known.
    pub line: Option<usize>,
    /// 1-based column, when the place is known.
    pub column: Option<usize>,
    /// Dotted key path, e.g. `patches.blend.conditions[2].curve`.
    pub key: String,
    /// What is wrong and what was expected.
    pub message: String,
    /// The offending source line (at most [`SNIPPET_CHARS`] characters of it around the
    /// column), for display.
    pub snippet: Option<String>,
    /// Characters of `snippet` before the caret.
    pub caret: usize,
}

/// Longest source excerpt an error shows (a 200 KB line is not echoed whole).
pub const SNIPPET_CHARS: usize = 120;
/// Longest message an error carries; longer ones (which quote hostile input) are cut.
pub const MESSAGE_CHARS: usize = 1000;

/// At most `max` characters of `s`, cut in the middle with a note of what was left out.
pub fn clip_message(s: &str, max: usize) -> String {
    let n = s.chars().count();
    if n <= max {
        return s.to_string();
    }
    let head: String = s.chars().take(max / 2).collect();
    let tail: String = s.chars().skip(n - max / 2).collect();
    format!("{head}… ({} characters left out) …{tail}", n - 2 * (max / 2))
}

impl std::error::Error for SceneError {}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.column {
                write!(f, ":{c}")?;
            }
        }
        write!(f, ": ")?;
        if !self.key.is_empty() {
            write!(f, "{}: ", self.key)?;
        }
        write!(f, "{}", self.message)?;
        if let (Some(s), Some(_)) = (&self.snippet, self.column) {
            write!(f, "\n  | {}\n  | {}^", s, " ".repeat(self.caret))?;
        }
        Ok(())
    }
}

/// Source text with a file label, for turning byte offsets into lines and columns.
#[derive(Clone, Debug)]
pub struct Source<'a> {
    /// The file label.
    pub file: &'a str,
    /// The text.
    pub text: &'a str,
}

impl Source<'_> {
    /// An error at byte `span` (or without a place).
    pub fn error(&self, span: Option<Range<usize>>, key: impl Into<String>, message: impl Into<String>) -> SceneError {
        let (line, column, snippet, caret) = match span {
            Some(r) => {
                let mut start = r.start.min(self.text.len());
                while !self.text.is_char_boundary(start) {
                    start -= 1;
                }
                let before = &self.text[..start];
                let line = before.matches('\n').count() + 1;
                let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
                let col = self.text[line_start..start].chars().count() + 1;
                let line_text = self.text[line_start..].lines().next().unwrap_or("");
                // a window of SNIPPET_CHARS characters around the column
                let n = line_text.chars().count();
                let from = (col - 1).saturating_sub(SNIPPET_CHARS / 2).min(n.saturating_sub(SNIPPET_CHARS));
                let mut s: String = line_text.chars().skip(from).take(SNIPPET_CHARS).collect();
                let mut caret = col - 1 - from;
                if from > 0 {
                    s.insert(0, '…');
                    caret += 1;
                }
                if from + SNIPPET_CHARS < n {
                    s.push('…');
                }
                (Some(line), Some(col), Some(s), caret)
            }
            None => (None, None, None, 0),
        };
        let key = clip_message(&key.into(), 200);
        let message = clip_message(&message.into(), MESSAGE_CHARS);
        SceneError { file: self.file.to_string(), line, column, key, message, snippet, caret }
    }
}
