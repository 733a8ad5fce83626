//! Integration tests: registration.
