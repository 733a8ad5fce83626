//! Integration tests: svg.
