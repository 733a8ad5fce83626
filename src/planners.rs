//! planners (in progress)
