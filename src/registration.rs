//! Rigid registration scanner -> printer (spec section 1). Placeholder: the
//! registration helper replaces this file, keeping these public names.
use glam::{DMat4, DVec3};
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RegistrationMethod {
    #[default]
    Lsq,
    Paper,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Registration {
    pub matrix: DMat4,
    pub residuals_mm: Vec<f64>,
    pub rms_mm: f64,
}

impl Registration {
    pub fn identity() -> Self {
        Registration {
            matrix: DMat4::IDENTITY,
            residuals_mm: Vec::new(),
            rms_mm: 0.0,
        }
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RegistrationError {
    #[error("registration needs at least 3 fiducials, got {0}")]
    TooFew(usize),
}

pub fn register(
    scan: &[DVec3],
    _printer: &[DVec3],
    _method: RegistrationMethod,
) -> Result<Registration, RegistrationError> {
    Err(RegistrationError::TooFew(scan.len()))
}
