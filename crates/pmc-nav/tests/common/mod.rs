//! Shared by the integration tests: the default planet's grid (built once per test binary), a
//! small deterministic random source, and points along a straight leg.
#![allow(dead_code)]

use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;
use pmc_nav::{Agent, NavGrid};
use pmc_planet::{Planet, PresetKind};
use std::sync::OnceLock;

/// The default planet (earthlike, seed 7, default layout).
pub fn default_planet() -> Planet {
    Planet::new(PresetKind::Earthlike, 7, Layout::default())
}

/// The default planet's grid for the default agent.
pub fn default_grid() -> &'static NavGrid {
    static GRID: OnceLock<NavGrid> = OnceLock::new();
    GRID.get_or_init(|| {
        let p = default_planet();
        NavGrid::build(p.density().as_ref(), p.layout(), Agent::default()).unwrap()
    })
}

/// A linear congruential generator: a fixed sequence per seed.
pub struct Lcg(pub u64);

impl Lcg {
    /// A number in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A direction, uniform enough over the sphere for tests.
    pub fn dir(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - DVec3::ONE;
            if v.length() > 0.1 && v.length() <= 1.0 {
                return v.normalize();
            }
        }
    }
}

/// The point at `t` of the straight leg from `a` to `b`: along the great circle, the radius
/// linear in the angle (written apart from the smoother's own).
pub fn leg_point(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    let (da, db) = (a.normalize(), b.normalize());
    let theta = da.angle_between(db);
    let dir = if theta < 1e-12 {
        da
    } else {
        (da * ((1.0 - t) * theta).sin() + db * (t * theta).sin()) / theta.sin()
    };
    dir * (a.length() + t * (b.length() - a.length()))
}
