//! Arguments echoed in errors, shortened.

/// At most `n` characters of `s` (errors do not echo long arguments whole).
pub fn clip(s: &str, n: usize) -> String {
    match s.char_indices().nth(n) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

/// An error message as it is shown: control characters (ANSI escapes, NUL, carriage
/// returns; not line breaks and tabs) written as `\u{…}` escapes, so hostile input echoed
/// in a message cannot drive the terminal, and at most `n` characters in all.
///
/// ```ignore
/// assert_eq!(printable("a\u{1b}[31mb\0", 100), "a\\u{1b}[31mb\\u{0}");
/// ```
pub fn printable(s: &str, n: usize) -> String {
    let mut out = String::with_capacity(s.len().min(4 * n));
    for (count, c) in s.chars().enumerate() {
        if count == n {
            out.push('…');
            break;
        }
        if c.is_control() && c != '\n' && c != '\t' {
            out.push_str(&c.escape_unicode().to_string());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped_and_long_messages_cut() {
        assert_eq!(printable("a\u{1b}[31mb\0c\nd", 100), "a\\u{1b}[31mb\\u{0}c\nd");
        assert_eq!(printable(&"x".repeat(5000), 10), format!("{}…", "x".repeat(10)));
        assert_eq!(clip("abcdef", 3), "abc…");
    }
}
