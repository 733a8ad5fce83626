//! Path sampling (spec section 3). Placeholder: the SVG helper replaces this
//! file, keeping these public names.
use glam::DVec2;

use crate::svg::Subpath2;

pub fn sample_subpath(sub: &Subpath2, _max_spacing_mm: f64) -> Vec<DVec2> {
    sub.points.clone()
}
