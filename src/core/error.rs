//! The core's error type. The C layer maps each kind to a `kdw_status` and keeps the message.

use std::fmt;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// An id that is null, stale (its object was destroyed) or belongs to another engine or kind.
    InvalidId,
    /// A value out of range: non-finite float, zero-length segment, wrong joint count, ...
    InvalidArgument,
    /// An arena ran out of id space.
    CapacityExceeded,
    /// An output buffer is smaller than what must be written.
    BufferTooSmall,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub kind: ErrorKind,
    pub message: String,
}

impl Error {
    pub fn invalid_argument(message: impl Into<String>) -> Self {
        Self { kind: ErrorKind::InvalidArgument, message: message.into() }
    }

    pub fn invalid_id(message: impl Into<String>) -> Self {
        Self { kind: ErrorKind::InvalidId, message: message.into() }
    }

    pub fn buffer_too_small(message: impl Into<String>) -> Self {
        Self { kind: ErrorKind::BufferTooSmall, message: message.into() }
    }

    pub fn capacity(message: impl Into<String>) -> Self {
        Self { kind: ErrorKind::CapacityExceeded, message: message.into() }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

pub type Result<T, E = Error> = std::result::Result<T, E>;
