//! Nozzle and process parameters, with the paper's values as defaults.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The dispensing tip. Defaults are the paper's 20-gauge tip.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Nozzle {
    /// Inner diameter d: also the target filament thickness and the
    /// constant stand-off (spec section 6a). Default 0.603 mm.
    pub inner_diameter_mm: f64,
    /// Outer diameter do: the diameter of the tip disk C_j tested against the
    /// surface (spec section 6c). Default 0.908 mm.
    pub outer_diameter_mm: f64,
}

impl Nozzle {
    /// 20-gauge tip, as printed in the paper.
    pub const DEFAULT: Nozzle = Nozzle {
        inner_diameter_mm: 0.603,
        outer_diameter_mm: 0.908,
    };

    pub fn with_inner_diameter_mm(mut self, d: f64) -> Self {
        self.inner_diameter_mm = d;
        self
    }

    pub fn with_outer_diameter_mm(mut self, d: f64) -> Self {
        self.outer_diameter_mm = d;
        self
    }

    /// Checks MIN_NOZZLE_MM <= d < do, both finite, d at most 10 mm and
    /// do at most 20.
    pub fn validate(&self) -> Result<()> {
        positive("nozzle inner diameter (mm)", self.inner_diameter_mm, 10.0)?;
        if self.inner_diameter_mm < MIN_NOZZLE_MM {
            // A diameter typed in metres (0.000603 for the paper's tip)
            // would be planned at a spacing of a fraction of a micrometre:
            // millions of samples a line, minutes of planning, and a
            // program for a nozzle that does not exist.
            return Err(Error::Parameter {
                name: "nozzle inner diameter (mm)",
                value: shown(self.inner_diameter_mm),
                reason: format!(
                    "must be at least {MIN_NOZZLE_MM} mm (1 um, the finest glass-capillary \
                     nozzles): the diameters are in mm (the paper's 20-gauge tip is 0.603; in \
                     metres it would be 0.000603)"
                ),
            });
        }
        positive("nozzle outer diameter (mm)", self.outer_diameter_mm, 20.0)?;
        if self.outer_diameter_mm <= self.inner_diameter_mm {
            return Err(Error::Parameter {
                name: "nozzle outer diameter (mm)",
                value: shown(self.outer_diameter_mm),
                reason: format!(
                    "must be larger than the inner diameter {}",
                    self.inner_diameter_mm
                ),
            });
        }
        Ok(())
    }
}

/// The finest nozzle inner diameter accepted (mm): 1 um, the finest
/// glass-capillary nozzles direct ink writing uses (the sampling spaces
/// such a path at [`crate::sampling::MIN_SPACING_MM`], no finer).
pub const MIN_NOZZLE_MM: f64 = 1e-3;

impl Default for Nozzle {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Process parameters. Defaults: tol = 0.1 mm, 5 mm/s, no dwell.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Process {
    /// User tolerance tol (spec sections 6c and 7). Default 0.1 mm.
    pub tolerance_mm: f64,
    /// Print speed. Default 5 mm/s (the paper prints at 2.5-5 mm/s).
    pub speed_mm_s: f64,
    /// Dwell after dispense-on and before dispense-off. Default 0 s.
    pub dwell_s: f64,
}

impl Process {
    pub const DEFAULT: Process = Process {
        tolerance_mm: 0.1,
        speed_mm_s: 5.0,
        dwell_s: 0.0,
    };

    pub fn with_tolerance_mm(mut self, tol: f64) -> Self {
        self.tolerance_mm = tol;
        self
    }

    pub fn with_speed_mm_s(mut self, v: f64) -> Self {
        self.speed_mm_s = v;
        self
    }

    pub fn validate(&self) -> Result<()> {
        positive("tolerance (mm)", self.tolerance_mm, 10.0)?;
        positive("speed (mm/s)", self.speed_mm_s, 1000.0)?;
        if !(self.dwell_s.is_finite() && (0.0..=600.0).contains(&self.dwell_s)) {
            return Err(Error::Parameter {
                name: "dwell (s)",
                value: shown(self.dwell_s),
                reason: "must be between 0 and 600 s".into(),
            });
        }
        Ok(())
    }
}

impl Default for Process {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A number as an error message shows what was typed: as written, but
/// past a million or under a ten-thousandth with an exponent (a speed of
/// 1e308 was a 309-digit number).
pub fn shown(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn positive(name: &'static str, v: f64, max: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 && v <= max {
        Ok(())
    } else {
        Err(Error::Parameter {
            name,
            value: shown(v),
            reason: format!("must be a number greater than 0 and at most {max}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diameter typed in metres (a QA run gave 0.0001, which planned for
    /// minutes) is refused, saying the value is in mm; 1 um is accepted.
    #[test]
    fn a_nozzle_finer_than_a_micrometre_is_refused_as_metres() {
        let n = |d: f64| {
            Nozzle::default()
                .with_inner_diameter_mm(d)
                .with_outer_diameter_mm(2.0 * d)
        };
        n(MIN_NOZZLE_MM).validate().unwrap();
        for d in [0.000603, 1e-4, 0.5 * MIN_NOZZLE_MM] {
            let e = n(d).validate().unwrap_err().to_string();
            assert!(
                e.contains("nozzle inner diameter (mm)")
                    && e.contains("at least 0.001 mm")
                    && e.contains("in metres it would be 0.000603"),
                "{e}"
            );
        }
    }

    #[test]
    fn defaults_are_the_papers_20_gauge_tip() {
        assert_eq!(Nozzle::default().inner_diameter_mm, 0.603);
        assert_eq!(Nozzle::default().outer_diameter_mm, 0.908);
        assert_eq!(Process::default().tolerance_mm, 0.1);
        assert_eq!(Process::default().speed_mm_s, 5.0);
        Nozzle::default().validate().unwrap();
        Process::default().validate().unwrap();
    }

    #[test]
    fn bad_nozzles_name_the_parameter() {
        let e = Nozzle::DEFAULT
            .with_outer_diameter_mm(0.5)
            .validate()
            .unwrap_err();
        assert!(e.to_string().contains("outer diameter"), "{e}");
        let e = Nozzle::DEFAULT
            .with_inner_diameter_mm(f64::NAN)
            .validate()
            .unwrap_err();
        assert!(e.to_string().contains("inner diameter"), "{e}");
        let e = Process::DEFAULT
            .with_speed_mm_s(-1.0)
            .validate()
            .unwrap_err();
        assert!(e.to_string().contains("speed"), "{e}");
    }

    /// A speed of 1e308 was shown in its error as a 309-digit number.
    #[test]
    fn huge_and_tiny_values_are_shown_with_an_exponent() {
        let e = Process::DEFAULT
            .with_speed_mm_s(1e308)
            .validate()
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "invalid parameter speed (mm/s) = 1e308: must be a number greater than 0 and at most 1000"
        );
        assert_eq!(shown(0.0001), "0.0001");
        assert_eq!(shown(0.00001234), "1.234e-5");
        assert_eq!(shown(-2.5), "-2.5");
        assert_eq!(shown(999999.0), "999999");
        assert_eq!(shown(f64::NAN), "NaN");
    }
}
