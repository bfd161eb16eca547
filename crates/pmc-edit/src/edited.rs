//! A density with brush operations applied: the edit overlay.
//!
//! [`EditedDensity`] wraps any [`Density`] and applies the shaping operations of an
//! [`EditSnapshot`] in order, each a pure function of the world position (see
//! [`BrushOp::apply`]). A sample is touched by an operation exactly when it lies strictly inside
//! the operation's [`BrushOp::reach`]; every other sample keeps the base density's bits. Chunks
//! therefore still agree bit for bit on the voxels they share, and a chunk whose padded samples all
//! lie outside an operation's reach meshes exactly as before it.

use crate::brush::{BrushKind, BrushOp};
use crate::log::EditSnapshot;
use crate::region::ConeShell;
use pmc_density::{Density, ShellColumns};
use pmc_geometry::glam::DVec3;

/// A density with the shaping operations of an edit snapshot applied, in order.
///
/// Paint operations do not change the density; [`paint_at`] reads them for shading.
///
/// Cost: a batch pays the base batch, one cheap test per operation, one per column for each
/// operation that meets the batch, and the brush formula for each sample inside a reach. Smoothing
/// reads the density before itself at six points by point calls through the base and the earlier
/// operations, so `m` overlapping smooth brushes cost `6^m` base point calls per sample in all of
/// them: correct, but keep stacks of overlapping smooth brushes short (or bake them into a new
/// base) until a cache exists.
#[derive(Clone, Debug)]
pub struct EditedDensity<D> {
    base: D,
    edits: EditSnapshot,
    /// Indices of the shaping (non-paint) operations.
    shaping: Vec<usize>,
    bounds: Option<(f64, f64)>,
}

impl<D: Density> EditedDensity<D> {
    /// `base` with the operations of `edits` applied.
    pub fn new(base: D, edits: EditSnapshot) -> EditedDensity<D> {
        let shaping: Vec<usize> = (0..edits.len()).filter(|i| edits[*i].shapes()).collect();
        // Outside every shaping ball the density is the base's, so the surface stays within the
        // base's bounds widened by the balls' radial extent. Remove only lowers the density (it can
        // open air below the lower bound, never add solid), add only raises it.
        let bounds = base.radial_bounds().map(|(mut lo, mut hi)| {
            for i in &shaping {
                let op = &edits[*i];
                let (r, reach) = (op.center.length(), op.reach());
                if op.kind != BrushKind::Add {
                    lo = lo.min((r - reach).max(0.0));
                }
                if op.kind != BrushKind::Remove {
                    hi = hi.max(r + reach);
                }
            }
            (lo, hi)
        });
        EditedDensity {
            base,
            edits,
            shaping,
            bounds,
        }
    }

    /// The unedited density.
    pub fn base(&self) -> &D {
        &self.base
    }

    /// The operations applied (paint included, though it does not change the density).
    pub fn edits(&self) -> &EditSnapshot {
        &self.edits
    }

    /// Applies the shaping operations, in order, to a batch that already holds the base density's
    /// batch for `dirs` × `radii` (exactly what `self.base().sample_shell(dirs, radii, out)`
    /// writes, for instance a copy of it kept from an earlier call). Base batch plus this is
    /// [`Density::sample_shell`] of the edited density, bit for bit; a caller that caches base
    /// batches (the base does not change when edits do) pays only for the edits.
    ///
    /// Each operation whose reach meets the batch's bounding cone shell applies only to the
    /// samples inside its reach (column by column: a column is skipped when its line misses the
    /// ball, and only the radii whose sample can lie in the ball are tested). Each operation's
    /// result is stored as `f32` before the next one applies, at every sample the same way, so
    /// the output is a function of the sample's position (and base value) alone.
    ///
    /// # Panics
    /// If `out.len() != dirs.len() * radii.len()`.
    pub fn apply_edits(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        assert_eq!(out.len(), dirs.len() * radii.len(), "output buffer has the wrong size");
        if self.shaping.is_empty() || dirs.is_empty() {
            return;
        }
        let bound = ConeShell::of_batch(dirs, radii);
        let n = dirs.len();
        for &i in &self.shaping {
            let op = &self.edits[i];
            let (c, reach) = (op.center, op.reach());
            if !bound.may_meet_ball(c, reach) {
                continue;
            }
            // Columns prefilter (generous); the exact test `q < reach` below decides,
            // identically for every batch.
            for (di, d) in dirs.iter().enumerate() {
                let Some((lo, hi)) = op.column_span(*d) else {
                    continue;
                };
                for (ri, r) in radii.iter().enumerate() {
                    if !(*r >= lo && *r <= hi) {
                        continue;
                    }
                    let p = *d * *r;
                    let q = (p - c).length();
                    if q < reach {
                        let o = &mut out[ri * n + di];
                        *o = op.apply(f64::from(*o), p, q, |x| self.density_before(i, x)) as f32;
                    }
                }
            }
        }
    }

    /// The density at `p` after the shaping operations before index `end` of the snapshot.
    fn density_before(&self, end: usize, p: DVec3) -> f64 {
        let mut d = self.base.density(p);
        for &i in &self.shaping {
            if i >= end {
                break;
            }
            d = self.apply_at(i, d, p);
        }
        d
    }

    /// Applies operation `i` to density `d` at `p` when `p` lies inside its reach.
    #[inline]
    fn apply_at(&self, i: usize, d: f64, p: DVec3) -> f64 {
        let op = &self.edits[i];
        let q = (p - op.center).length();
        if q < op.reach() {
            op.apply(d, p, q, |x| self.density_before(i, x))
        } else {
            d
        }
    }
}

impl<D: Density> Density for EditedDensity<D> {
    fn density(&self, p: DVec3) -> f64 {
        self.density_before(usize::MAX, p)
    }

    /// The base batch, then [`EditedDensity::apply_edits`]: each shaping operation whose reach
    /// meets the batch's bounding cone shell, applied only to the samples inside its reach.
    fn sample_shell(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32]) {
        self.base.sample_shell(dirs, radii, out);
        self.apply_edits(dirs, radii, out);
    }

    /// The base batch keeping its columns (edits change voxels, not the base's columns), then
    /// the edits.
    fn sample_shell_keeping(&self, dirs: &[DVec3], radii: &[f64], out: &mut [f32], columns: &mut ShellColumns) {
        self.base.sample_shell_keeping(dirs, radii, out, columns);
        self.apply_edits(dirs, radii, out);
    }

    /// The base's answer when no shaping operation's reach meets the batch's bounding cone
    /// shell (then every sample keeps the base's bits), else `None`.
    fn uniform_sign(&self, dirs: &[DVec3], radii: &[f64]) -> Option<bool> {
        if !self.shaping.is_empty() && !dirs.is_empty() {
            let bound = ConeShell::of_batch(dirs, radii);
            if self
                .shaping
                .iter()
                .any(|&i| bound.may_meet_ball(self.edits[i].center, self.edits[i].reach()))
            {
                return None;
            }
        }
        self.base.uniform_sign(dirs, radii)
    }

    fn radial_bounds(&self) -> Option<(f64, f64)> {
        self.bounds
    }
}

/// The paint at world point `p`: the material and strength of the last paint operation of `ops`
/// whose ball (radius [`BrushOp::radius`], strictly inside) holds `p`, if any.
pub fn paint_at(ops: &[BrushOp], p: DVec3) -> Option<(u8, f64)> {
    ops.iter().rev().find_map(|op| match op.kind {
        BrushKind::Paint { material } if (p - op.center).length() < op.reach() => Some((material, op.strength)),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_density::{FnDensity, Sphere};
    use proptest::prelude::*;

    const R: f64 = 100.0;

    fn op(kind: BrushKind, c: DVec3, radius: f64, strength: f64) -> BrushOp {
        BrushOp::new(kind, c, radius, strength).unwrap()
    }

    fn kinds() -> [BrushKind; 5] {
        [
            BrushKind::Add,
            BrushKind::Remove,
            BrushKind::Smooth,
            BrushKind::Flatten,
            BrushKind::Paint { material: 1 },
        ]
    }

    fn wavy() -> FnDensity<impl Fn(DVec3) -> f64 + Send + Sync> {
        FnDensity(|p: DVec3| R - p.length() + 3.0 * (p.x * 0.3).sin() * (p.z * 0.2).cos())
    }

    #[test]
    fn remove_digs_and_add_fills_exact_balls() {
        let top = DVec3::Y * R;
        let dig = EditedDensity::new(Sphere { radius: R }, vec![op(BrushKind::Remove, top, 10.0, 1.0)].into());
        assert!(
            (dig.density(top) + 10.0).abs() < 1e-12,
            "centre 10 m from the ball's surface"
        );
        assert!(dig.density(top - DVec3::Y * 9.9) < 0.0);
        assert!(dig.density(top - DVec3::Y * 10.1) > 0.0);
        assert_eq!(dig.density(top - DVec3::Y * 30.0), 30.0, "outside the reach: the base");
        // Half strength: a ball of half the radius.
        let half = EditedDensity::new(Sphere { radius: R }, vec![op(BrushKind::Remove, top, 10.0, 0.5)].into());
        assert!(half.density(top - DVec3::Y * 4.9) < 0.0 && half.density(top - DVec3::Y * 5.1) > 0.0);
        let fill = EditedDensity::new(Sphere { radius: R }, vec![op(BrushKind::Add, top, 10.0, 1.0)].into());
        assert!(fill.density(top + DVec3::Y * 9.9) > 0.0 && fill.density(top + DVec3::Y * 10.1) < 0.0);
        assert!((fill.density(top + DVec3::Y * 5.0) - 5.0).abs() < 1e-12);
        // Bounds widen to hold the edits.
        assert_eq!(dig.radial_bounds(), Some((R - 12.5, R)));
        assert_eq!(fill.radial_bounds(), Some((R, R + 12.5)));
    }

    #[test]
    fn flatten_levels_toward_the_plane_and_paint_changes_nothing() {
        let c = DVec3::Y * R;
        let f = EditedDensity::new(wavy(), vec![op(BrushKind::Flatten, c, 8.0, 1.0)].into());
        // At the centre the weight is 1: the plane's distance, 0.
        assert!(f.density(c).abs() < 1e-12);
        assert!(
            (f.density(c - DVec3::Y * 2.0) - 2.0).abs() < 1e-12,
            "positive below the plane"
        );
        let p = EditedDensity::new(wavy(), vec![op(BrushKind::Paint { material: 2 }, c, 8.0, 1.0)].into());
        let w = wavy();
        assert_eq!(p.density(c), w.density(c));
        assert_eq!(p.radial_bounds(), None);
        assert_eq!(paint_at(p.edits(), c + DVec3::X), Some((2, 1.0)));
        assert_eq!(paint_at(p.edits(), c + DVec3::X * 8.0), None);
    }

    #[test]
    fn smoothing_moves_toward_the_local_mean() {
        // A spike field: smoothing pulls the spike toward its neighbours.
        let spike = FnDensity(|p: DVec3| if (p - DVec3::Y * R).length() < 0.5 { 10.0 } else { -1.0 });
        let c = DVec3::Y * R;
        let s = EditedDensity::new(spike, vec![op(BrushKind::Smooth, c, 4.0, 1.0)].into());
        assert!((s.density(c) - -1.0).abs() < 1e-12, "the neighbours at 1 m are all -1");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// The batch call equals point calls (to f32 rounding), equals the base batch followed by
        /// `apply_edits` bit for bit, leaves samples outside every reach bit-identical to the base,
        /// and is continuous across each brush's edge.
        #[test]
        fn batch_matches_points_and_is_local(
            kinds_idx in proptest::collection::vec(0usize..5, 1..5),
            seeds in proptest::collection::vec([-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, 1.0f64..12.0, 0.1f64..1.0], 4),
        ) {
            let ops: Vec<BrushOp> = kinds_idx.iter().zip(&seeds).map(|(k, s)| {
                let dir = (DVec3::new(s[0], 1.0, s[1]) * 0.3 + DVec3::Y).normalize();
                op(kinds()[*k], dir * (R + s[2] * 4.0), s[3], s[4])
            }).collect();
            let e = EditedDensity::new(wavy(), ops.clone().into());
            let dirs: Vec<DVec3> = (0..24).flat_map(|a| (0..24).map(move |b| {
                DVec3::new((a as f64 - 12.0) * 0.01, 1.0, (b as f64 - 12.0) * 0.01).normalize()
            })).collect();
            let radii: Vec<f64> = (0..16).map(|k| R - 8.0 + k as f64).collect();
            let mut got = vec![0.0f32; dirs.len() * radii.len()];
            let mut base = got.clone();
            e.sample_shell(&dirs, &radii, &mut got);
            wavy().sample_shell(&dirs, &radii, &mut base);
            // The edits applied over a copy of the base batch: the same bits.
            let mut over = vec![0.0f32; got.len()];
            e.base().sample_shell(&dirs, &radii, &mut over);
            e.apply_edits(&dirs, &radii, &mut over);
            prop_assert!(over.iter().zip(&got).all(|(a, b)| a.to_bits() == b.to_bits()));
            for (ri, r) in radii.iter().enumerate() {
                for (di, d) in dirs.iter().enumerate() {
                    let p = *d * *r;
                    let i = ri * dirs.len() + di;
                    let touched = ops.iter().any(|o| o.shapes() && (p - o.center).length() < o.reach());
                    if !touched {
                        prop_assert_eq!(got[i].to_bits(), base[i].to_bits());
                    }
                    let point = e.density(p);
                    prop_assert!((f64::from(got[i]) - point).abs() <= 1e-4 * (1.0 + point.abs()), "{} vs {point}", got[i]);
                }
            }
            // Continuity at the edge of the reach: just inside and just outside agree.
            for o in &ops {
                let dir = DVec3::new(0.3, 0.5, -0.8).normalize();
                let inside = o.center + dir * (o.reach() * (1.0 - 1e-7));
                let outside = o.center + dir * (o.reach() * (1.0 + 1e-7));
                let (a, b) = (e.density(inside), e.density(outside));
                prop_assert!((a - b).abs() < 1e-3, "{:?}: {a} vs {b}", o.kind);
            }
        }
    }
}
