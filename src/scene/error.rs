//! Scene errors that name the file, the line and the field.

use std::fmt;
use std::path::{Path, PathBuf};

/// One step of a path into the scene document: a key or an array index.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FieldSegment {
    /// A table key.
    Key(String),
    /// An element of an array (or array of tables).
    Index(usize),
}

/// Where a value sits in the scene document, e.g. `wall[2].motion.rpm`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FieldPath(pub Vec<FieldSegment>);

impl FieldPath {
    /// The path of a top-level key.
    pub fn root(key: &str) -> Self {
        FieldPath(vec![FieldSegment::Key(key.to_string())])
    }

    /// This path extended by a key.
    pub fn key(&self, key: &str) -> Self {
        let mut p = self.clone();
        p.0.push(FieldSegment::Key(key.to_string()));
        p
    }

    /// This path extended by an index.
    pub fn index(&self, i: usize) -> Self {
        let mut p = self.clone();
        p.0.push(FieldSegment::Index(i));
        p
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (k, seg) in self.0.iter().enumerate() {
            match seg {
                FieldSegment::Key(key) if k == 0 => write!(f, "{key}")?,
                FieldSegment::Key(key) => write!(f, ".{key}")?,
                FieldSegment::Index(i) => write!(f, "[{i}]")?,
            }
        }
        Ok(())
    }
}

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The TOML is malformed or a field has the wrong type or name.
    #[error("{}:{line}:{column}: {message}", file.display())]
    Syntax {
        /// The file.
        file: PathBuf,
        /// Line (1-based).
        line: usize,
        /// Column (1-based).
        column: usize,
        /// What the parser said.
        message: String,
    },
    /// A value is well-formed but unusable.
    #[error("{}:{line}: {field}: {message}", file.display())]
    Invalid {
        /// The file.
        file: PathBuf,
        /// Line of the field (1-based; 0 where it could not be found).
        line: usize,
        /// The field.
        field: FieldPath,
        /// What is wrong.
        message: String,
    },
}

impl SceneError {
    /// The line the error points to (0 for none).
    pub fn line(&self) -> usize {
        match self {
            SceneError::Io { .. } => 0,
            SceneError::Syntax { line, .. } | SceneError::Invalid { line, .. } => *line,
        }
    }
}

/// A field-level problem found while validating, before it is placed in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldError {
    /// The field.
    pub field: FieldPath,
    /// What is wrong.
    pub message: String,
}

impl FieldError {
    /// A problem with `field`.
    pub fn new(field: FieldPath, message: impl Into<String>) -> Self {
        FieldError {
            field,
            message: message.into(),
        }
    }

    /// Places the error in `file` whose text is `text`.
    pub fn locate(self, file: &Path, text: &str) -> SceneError {
        SceneError::Invalid {
            file: file.to_path_buf(),
            line: super::locate::line_of(text, &self.field).unwrap_or(0),
            field: self.field,
            message: self.message,
        }
    }
}

/// 1-based line and column of byte `offset` in `text`.
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |p| p + 1) + 1;
    (line, column)
}
