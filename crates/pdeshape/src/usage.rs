//! Usage errors found after parsing: flags that do not go together with the scene or the
//! output (`--degree` with a mesh output, an unknown output extension). The CLI exits 2 for
//! them, as for the errors clap finds, and 1 for runtime and input errors.

/// A usage error (exit code 2).
#[derive(Debug)]
pub struct Usage(pub String);

impl std::fmt::Display for Usage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Usage {}

/// A [`Usage`] error.
pub fn usage(msg: impl Into<String>) -> anyhow::Error {
    anyhow::Error::new(Usage(msg.into()))
}
