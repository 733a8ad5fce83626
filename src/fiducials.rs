//! Fiducial holes as boundary loops (spec section 2). Placeholder: the
//! registration helper replaces this file, keeping these public names.
use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::mesh::TriMesh;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fiducial {
    pub centroid: DVec3,
    pub diameter_mm: f64,
    pub loop_len: usize,
}

pub fn find_fiducials(_mesh: &TriMesh) -> Vec<Fiducial> {
    Vec::new()
}
