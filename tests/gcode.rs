//! Integration tests: gcode.
