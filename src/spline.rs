//! spline (in progress)
