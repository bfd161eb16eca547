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

/// Why agent limits were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AgentError {
    /// Clearance is not a finite number above 0.
    #[error("agent clearance {0} must be a finite number of metres above 0")]
    Clearance(f64),
    /// A step limit is not a finite number of at least 0.
    #[error("agent step {0} must be a finite number of metres, at least 0")]
    Step(f64),
    /// The slope is not in `(0, 90]`.
    #[error("agent max slope {0} must be above 0 and at most 90 degrees")]
    Slope(f64),
}

impl Agent {
    /// Checks the limits.
    pub fn validate(&self) -> Result<(), AgentError> {
        if !(self.clearance.is_finite() && self.clearance > 0.0) {
            return Err(AgentError::Clearance(self.clearance));
        }
        for s in [self.step_up, self.step_down] {
            if !(s.is_finite() && s >= 0.0) {
                return Err(AgentError::Step(s));
            }
        }
        if !(self.max_slope > 0.0 && self.max_slope <= 90.0) {
            return Err(AgentError::Slope(self.max_slope));
        }
        Ok(())
    }
}
