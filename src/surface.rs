//! surface (in progress)
