use std::fmt;
use std::path::PathBuf;

/// A scene that cannot be read or built: where (file, line, column, when
/// known) and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct SceneError {
    pub file: Option<PathBuf>,
    /// 1-based line and column.
    pub location: Option<(usize, usize)>,
    pub message: String,
}

impl SceneError {
    pub fn new(message: impl Into<String>) -> Self {
        SceneError { file: None, location: None, message: message.into() }
    }

    /// The error at byte offset `offset` of `text`.
    pub fn at(text: &str, offset: usize, message: impl Into<String>) -> Self {
        SceneError { file: None, location: Some(line_col(text, offset)), message: message.into() }
    }

    pub fn in_file(mut self, file: impl Into<PathBuf>) -> Self {
        self.file = Some(file.into());
        self
    }
}

/// 1-based line and column (in characters) of a byte offset.
pub fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &text[..offset];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (line, before[line_start..].chars().count() + 1)
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (&self.file, self.location) {
            (Some(file), Some((line, col))) => write!(f, "{}:{line}:{col}: ", file.display())?,
            (Some(file), None) => write!(f, "{}: ", file.display())?,
            (None, Some((line, col))) => write!(f, "line {line}, column {col}: ")?,
            (None, None) => {}
        }
        f.write_str(&self.message)
    }
}
