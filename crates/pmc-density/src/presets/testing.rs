//! Shared checks for the preset tests.

use super::Terrain;
use crate::Density;
use pmc_geometry::glam::DVec3;
use pmc_geometry::Layout;

/// `n` directions spread evenly over the sphere (a Fibonacci lattice), with a small irrational
/// twist so they avoid the coordinate planes.
pub(crate) fn sphere_dirs(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let rho = (1.0 - y * y).sqrt();
            let a = golden * i as f64 + 0.1234;
            DVec3::new(rho * a.cos(), y, rho * a.sin()).normalize()
        })
        .collect()
}

/// A chunk-like patch: `n x n` unit directions around `centre`, `step` radians apart, and `nr`
/// radii from `r0` every `dr`.
pub(crate) fn patch(centre: DVec3, step_len: f64, n: usize, r0: f64, dr: f64, nr: usize) -> (Vec<DVec3>, Vec<f64>) {
    let u = centre.any_orthonormal_vector();
    let v = centre.cross(u);
    let step = step_len / r0;
    let half = (n as f64 - 1.0) / 2.0;
    let mut dirs = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            dirs.push((centre + u * ((i as f64 - half) * step) + v * ((j as f64 - half) * step)).normalize());
        }
    }
    (dirs, (0..nr).map(|k| r0 + k as f64 * dr).collect())
}

/// Number of sign changes of the density along `dir` from radius `lo` to `hi` in steps of `step`.
pub(crate) fn sign_changes(d: &dyn Density, dir: DVec3, lo: f64, hi: f64, step: f64) -> usize {
    let mut changes = 0;
    let mut prev = d.density(dir * lo) > 0.0;
    let mut r = lo;
    while r < hi {
        r += step;
        let s = d.density(dir * r) > 0.0;
        if s != prev {
            changes += 1;
        }
        prev = s;
    }
    changes
}

/// The batch call equals point calls (within `tol`; nearly always bit for bit) and is
/// deterministic, also from another thread.
pub(crate) fn check_batch_matches_points(
    d: &(dyn Density + 'static),
    (dirs, radii): &(Vec<DVec3>, Vec<f64>),
    tol: f32,
) {
    let mut a = vec![0.0f32; dirs.len() * radii.len()];
    d.sample_shell(dirs, radii, &mut a);
    let mut b = vec![0.0f32; a.len()];
    d.sample_shell(dirs, radii, &mut b);
    assert!(
        a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
        "batch is not deterministic"
    );
    let c = std::thread::scope(|s| {
        s.spawn(|| {
            let mut c = vec![0.0f32; dirs.len() * radii.len()];
            d.sample_shell(dirs, radii, &mut c);
            c
        })
        .join()
        .unwrap()
    });
    assert!(
        a.iter().zip(&c).all(|(x, y)| x.to_bits() == y.to_bits()),
        "batch differs across threads"
    );
    let mut exact = 0;
    let (mut solid, mut air) = (0, 0);
    for (k, r) in radii.iter().enumerate() {
        for (i, dir) in dirs.iter().enumerate() {
            let v = a[k * dirs.len() + i];
            let p = d.density(*dir * *r) as f32;
            assert!((v - p).abs() <= tol, "batch {v} vs point {p} at dir {dir} r {r}");
            if v.to_bits() == p.to_bits() {
                exact += 1;
            }
            if v > 0.0 {
                solid += 1;
            } else {
                air += 1;
            }
        }
    }
    assert!(
        exact * 100 >= a.len() * 95,
        "only {exact} of {} samples are bit-identical",
        a.len()
    );
    assert!(solid > 0 && air > 0, "the patch should hold surface");
}

/// The surface lies within the radial bounds, which lie within the shell: along many radial
/// lines everything below the lower bound is solid, everything above the upper bound is air,
/// layer 0 is solid and the top layer is air.
pub(crate) fn check_surface_within_bounds(t: &Terrain, layout: &Layout) {
    let d = &*t.density;
    let (lo, hi) = d.radial_bounds().expect("presets have bounds");
    assert!(lo <= hi);
    assert!(
        lo > layout.d_b() && hi < layout.radius(),
        "bounds ({lo}, {hi}) leave the shell"
    );
    let l_d = layout.l_d();
    for dir in sphere_dirs(1500) {
        assert!(d.density(dir * layout.d_b()) > 0.0, "layer 0 is not solid");
        assert!(d.density(dir * layout.radius()) <= 0.0, "the top layer is not air");
        let mut r = layout.d_b();
        while r < layout.radius() {
            let v = d.density(dir * r);
            if r < lo {
                assert!(v > 0.0, "air below the lower bound at {r}");
            }
            if r > hi {
                assert!(v <= 0.0, "solid above the upper bound at {r}");
            }
            r += 0.25 * l_d;
        }
    }
}

/// Different seeds give different terrain.
pub(crate) fn check_seeds_differ(a: &dyn Density, b: &dyn Density, layout: &Layout) {
    let r = 0.5 * (layout.d_b() + layout.radius());
    let (lo, hi) = a.radial_bounds().unwrap();
    let mut differ = 0;
    let dirs = sphere_dirs(500);
    for dir in &dirs {
        let r = r.clamp(lo, hi);
        if (a.density(*dir * r) - b.density(*dir * r)).abs() > 1e-3 {
            differ += 1;
        }
    }
    assert!(
        differ > dirs.len() * 9 / 10,
        "only {differ} of {} samples differ",
        dirs.len()
    );
}
