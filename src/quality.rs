//! quality (in progress)
