//! Arguments echoed in errors, shortened.

/// At most `n` characters of `s` (errors do not echo long arguments whole).
pub fn clip(s: &str, n: usize) -> String {
    match s.char_indices().nth(n) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}
