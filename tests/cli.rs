//! Integration tests: the pcpp command-line tool.
