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
    /// The offending source line, for display.
    pub snippet: Option<String>,
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
        if let (Some(s), Some(c)) = (&self.snippet, self.column) {
            write!(f, "\n  | {}\n  | {}^", s, " ".repeat(c.saturating_sub(1)))?;
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
        let (line, column, snippet) = match span {
            Some(r) => {
                let start = r.start.min(self.text.len());
                let before = &self.text[..start];
                let line = before.matches('\n').count() + 1;
                let line_start = before.rfind('\n').map(|i| i + 1).unwrap_or(0);
                let col = self.text[line_start..start].chars().count() + 1;
                let line_text = self.text[line_start..].lines().next().unwrap_or("").to_string();
                (Some(line), Some(col), Some(line_text))
            }
            None => (None, None, None),
        };
        SceneError { file: self.file.to_string(), line, column, key: key.into(), message: message.into(), snippet }
    }
}
