//! All integration tests in one binary, a module per area (as parry does).
mod bruteforce;
mod cli;
mod fuzz_regressions;
mod gcode;
mod importers;
mod planning;
mod pointcloud;
mod properties;
mod realworld;
mod registration;
mod safety;
mod svg;
