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

/// A digest of every way `t`'s shader colours points near its surface: point by point, on the
/// surface, in batches, a chunk's edge vertices (with and without the columns its density batch
/// kept) and each material by id. Pins a terrain's look bit for bit.
pub(crate) fn shade_digest(t: &Terrain, layout: &Layout) -> u64 {
    use super::{EdgeVertices, Shade};
    use crate::ShellColumns;
    use pmc_geometry::VertexEdge;
    let d = &*t.density;
    let (lo, hi) = d.radial_bounds().expect("presets have bounds");
    let l_d = layout.l_d();
    let dirs = sphere_dirs(1200);
    // The surface along each direction (the highest solid sample of a batch over the shell,
    // refined by bisection), and points around it: deep under (caves), on it, above it.
    let surface = surfaces(d, &dirs, lo, hi);
    let offsets = [-40.0, -6.0, -2.5, -1.2, -0.3, 0.0, 0.4, 1.5];
    let mut points = Vec::new();
    let mut normals = Vec::new();
    for (i, (dir, h)) in dirs.iter().zip(&surface).enumerate() {
        for (k, z) in offsets.iter().enumerate() {
            let tilt = [0.0, 0.4, 0.9, 1.7][(i + k) % 4];
            points.push(*dir * (h + z * l_d));
            normals.push((*dir + dir.any_orthonormal_vector() * tilt).normalize());
        }
    }
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |s: &Shade| {
        for b in s.color.iter().chain([&s.material]) {
            hash = (hash ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3);
        }
    };
    for (p, n) in points.iter().zip(&normals) {
        eat(&t.shader.shade(*p, *n));
        eat(&t.shader.shade_on_surface(*p, *n));
    }
    let mut out = Vec::new();
    for on_surface in [false, true] {
        t.shader.shade_many(&points, &normals, on_surface, &mut out);
        out.iter().for_each(&mut eat);
    }
    // Edge vertices between neighbouring directions of a chunk-like patch at the highest
    // surface found, around it.
    let top = (0..dirs.len())
        .max_by(|a, b| surface[*a].total_cmp(&surface[*b]))
        .unwrap();
    let (pdirs, _) = patch(dirs[top], 2.0 * l_d, 24, hi, l_d, 1);
    let psurf = surfaces(d, &pdirs, lo, hi);
    let n = pdirs.len() as u32;
    let edges: Vec<VertexEdge> = (0..n)
        .flat_map(|i| {
            [
                VertexEdge { a: i, b: i, t: 0.3 },
                VertexEdge {
                    a: i,
                    b: (i + 1) % n,
                    t: f64::from(i % 7) / 6.0,
                },
                VertexEdge {
                    a: i,
                    b: (i + 24) % n,
                    t: 0.5,
                },
            ]
        })
        .collect();
    let epoints: Vec<DVec3> = edges
        .iter()
        .enumerate()
        .map(|(k, e)| {
            let (a, b) = (pdirs[e.a as usize], pdirs[e.b as usize]);
            let h = psurf[e.a as usize] + (psurf[e.b as usize] - psurf[e.a as usize]) * e.t;
            (a + (b - a) * e.t).normalize() * (h + offsets[k % offsets.len()] * l_d)
        })
        .collect();
    let enormals: Vec<DVec3> = epoints
        .iter()
        .enumerate()
        .map(|(k, p)| (p.normalize() + DVec3::X * [0.0, 0.5, 1.2][k % 3]).normalize())
        .collect();
    let radii: Vec<f64> = (0..4).map(|k| lo + (hi - lo) * f64::from(k) / 3.0).collect();
    let mut kept = ShellColumns::default();
    let mut values = vec![0.0f32; pdirs.len() * radii.len()];
    d.sample_shell_keeping(&pdirs, &radii, &mut values, &mut kept);
    for columns in [&kept, &ShellColumns::default()] {
        let v = EdgeVertices {
            points: &epoints,
            normals: &enormals,
            edges: &edges,
            dirs: &pdirs,
            columns,
        };
        t.shader.shade_edges(&v, &mut out);
        out.iter().for_each(&mut eat);
    }
    for id in 0..=t.materials.len() as u8 {
        for p in points.iter().step_by(97) {
            eat(&t.shader.shade_material(id, *p));
        }
    }
    hash
}

/// Along each of `dirs`, a radius between `lo` and `hi` where the density changes sign (the
/// highest such change a batch of 256 radii finds, refined by bisection; `lo` where none).
fn surfaces(d: &dyn Density, dirs: &[DVec3], lo: f64, hi: f64) -> Vec<f64> {
    let radii: Vec<f64> = (0..256).map(|k| lo + (hi - lo) * f64::from(k) / 255.0).collect();
    let mut v = vec![0.0f32; dirs.len() * radii.len()];
    d.sample_shell(dirs, &radii, &mut v);
    dirs.iter()
        .enumerate()
        .map(|(i, dir)| {
            let Some(k) = (0..radii.len()).rev().find(|k| v[k * dirs.len() + i] > 0.0) else {
                return lo;
            };
            let (mut a, mut b) = (radii[k], radii[(k + 1).min(radii.len() - 1)]);
            for _ in 0..30 {
                let m = 0.5 * (a + b);
                if d.density(*dir * m) > 0.0 {
                    a = m;
                } else {
                    b = m;
                }
            }
            a
        })
        .collect()
}
