//! Antenna path generators (placeholder).
