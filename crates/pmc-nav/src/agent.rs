//! The walking agent's limits.

/// What an agent can do: how much head room it needs, how high it can step up and down between
/// neighbouring columns, and how steep a slope it can walk. Metres and degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Agent {
    /// Air needed above the ground where the agent stands and along each step, metres (above 0).
    pub clearance: f64,
    /// Largest rise between neighbouring surface points, metres (at least 0).
    pub step_up: f64,
    /// Largest drop between neighbouring surface points, metres (at least 0).
    pub step_down: f64,
    /// Steepest slope walked, degrees, in `(0, 90]`.
    pub max_slope: f64,
}

impl Default for Agent {
    /// A person-sized agent on the default layout (columns about 12 m apart, layers 4 m): 2 m of
    /// clearance, 8 m steps up and down, slopes up to 45 degrees.
    fn default() -> Self {
        Agent {
            clearance: 2.0,
            step_up: 8.0,
            step_down: 8.0,
            max_slope: 45.0,
        }
    }
}

/// The largest clearance and steps an agent may have, metres. Larger ones are refused: the
/// grid's checks read that many layers per column (a clearance of 10^16 m hung `/path`).
pub const MAX_AGENT_METRES: f64 = 1000.0;

/// Why agent limits were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AgentError {
    /// Clearance is not a finite number above 0 and at most [`MAX_AGENT_METRES`].
    #[error("agent clearance {0} must be a finite number of metres above 0 and at most {MAX_AGENT_METRES}")]
    Clearance(f64),
    /// A step limit is not a finite number from 0 to [`MAX_AGENT_METRES`].
    #[error("agent step {0} must be a finite number of metres from 0 to {MAX_AGENT_METRES}")]
    Step(f64),
    /// The slope is not in `(0, 90]`.
    #[error("agent max slope {0} must be above 0 and at most 90 degrees")]
    Slope(f64),
}

impl Agent {
    /// Checks the limits.
    pub fn validate(&self) -> Result<(), AgentError> {
        if !(self.clearance > 0.0 && self.clearance <= MAX_AGENT_METRES) {
            return Err(AgentError::Clearance(self.clearance));
        }
        for s in [self.step_up, self.step_down] {
            if !(0.0..=MAX_AGENT_METRES).contains(&s) {
                return Err(AgentError::Step(s));
            }
        }
        if !(self.max_slope > 0.0 && self.max_slope <= 90.0) {
            return Err(AgentError::Slope(self.max_slope));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `GET /api/v1/path?...&clearance=18744073709555516.8` hung the server (found by `cargo fuzz`,
    /// `fuzz/regressions/http_request/huge-clearance`): a clearance or a step the grid would read
    /// that many layers for is refused.
    #[test]
    fn limits_beyond_a_kilometre_or_not_numbers_are_refused() {
        let a = Agent::default();
        assert!(a.validate().is_ok());
        for clearance in [0.0, -1.0, f64::NAN, f64::INFINITY, 1000.001, 1.874_407_370_955_551_6e16] {
            let e = Agent { clearance, ..a }.validate().unwrap_err();
            assert!(e.to_string().contains("at most 1000"), "{e}");
        }
        assert!(Agent { clearance: 1000.0, ..a }.validate().is_ok());
        for step in [-0.5, f64::NAN, 1e9] {
            assert!(Agent { step_up: step, ..a }.validate().is_err());
            assert!(Agent { step_down: step, ..a }.validate().is_err());
        }
        assert!(Agent {
            step_up: 0.0,
            step_down: 1000.0,
            ..a
        }
        .validate()
        .is_ok());
    }
}
