//! Scene errors: every one names the file, and where it can, the line, the
//! table entry (`spring[3]`) and the field.

use std::fmt;

/// Something wrong with a scene file.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    /// The file, as the user named it.
    pub file: String,
    /// 1-based line of the offending entry or key, when known.
    pub line: Option<usize>,
    /// The table entry, e.g. `spring[3]` (0-based) or `world`.
    pub entry: Option<String>,
    /// The field within the entry, e.g. `stiffness`.
    pub field: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl SceneError {
    /// An error about the file as a whole.
    pub fn file(file: &str, message: impl Into<String>) -> Self {
        SceneError {
            file: file.to_string(),
            line: None,
            entry: None,
            field: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        write!(f, ": ")?;
        let entry = self.entry.as_deref().filter(|e| !e.is_empty());
        let field = self.field.as_deref().filter(|k| !k.is_empty());
        match (entry, field) {
            (Some(e), Some(k)) => write!(f, "{e}.{k}: ")?,
            (Some(e), None) => write!(f, "{e}: ")?,
            (None, Some(k)) => write!(f, "{k}: ")?,
            (None, None) => {}
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for SceneError {}
