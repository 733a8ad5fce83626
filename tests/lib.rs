//! All integration tests in one binary, a module per area (as parry does).
mod cli;
mod gcode;
mod importers;
mod planning;
mod realworld;
mod registration;
mod svg;
