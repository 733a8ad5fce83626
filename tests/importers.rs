//! Integration tests: importers.
