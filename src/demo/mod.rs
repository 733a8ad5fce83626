//! Built-in demo inputs, generated (no files a user must find).
pub mod antennas;
pub mod test_part;
