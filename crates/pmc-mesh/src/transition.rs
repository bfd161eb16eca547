//! Closed seams between levels of detail: transition patches.
//!
//! # The seam contract
//!
//! A level-`L` chunk and a level-`L + 1` neighbour meet on a plane of the grid (a chunk side,
//! possibly on a face edge). The coarse chunk cuts that plane with marching squares on its
//! coarse squares (four level-`L + 1` voxels); the fine chunk cuts the same region with marching
//! squares on four times as many fine squares. The two contours differ, so the meshes alone leave
//! a crack. The fine chunk closes it with a *transition patch* per coarse square, lying in the
//! plane: the region where the two sides disagree about what is solid.
//!
//! Take the solid region of the square as the coarse side sees it, `R_c`, and as the fine side
//! sees it, `R_f`. The combined solid is `R_c`'s side of the coarse mesh joined to `R_f`'s side of
//! the fine mesh; its boundary needs, in the plane, exactly `R_c − R_f` (as a signed 2-chain).
//! The boundary of that chain is made of
//!
//! - the coarse contour of the square (the marching-squares rule of [`crate::tables`]: diagonally
//!   opposite solid corners are kept apart), oriented with the solid on its left;
//! - the fine contours of the four sub-squares (the same rule), reversed;
//! - along the square's border, the intervals where exactly one side is solid, forward when the
//!   coarse side is: the *bridges*.
//!
//! These segments chain into loops (every cut vertex has one segment in and one out), and each
//! loop is triangulated in the plane by ear clipping, keeping its orientation, so a region solid
//! only on the coarse side faces the fine side and the converse.
//!
//! Every vertex of a patch is the vertex of a grid edge: a fine edge (the fine chunk's own, same
//! bits) or a coarse edge (the coarse chunk's, same bits: its position and density come from
//! its canonical voxels, its gradient from the coarse chunk's frame through
//! [`crate::voxel_gradient`], supplied by the caller). The bridges on a border line are computed
//! from that line's three samples only, walked in canonical order, so the patches on either side
//! of a line, in the same plane or in two planes meeting at a chunk edge, produce the same
//! segments in opposite directions. The union of the selected chunks is then a closed 2-manifold
//! when vertices are identified by edge key, provided no chunk edge has four chunks around it
//! alternating fine, coarse, fine, coarse (the solid would touch itself along the line); the
//! level-of-detail selection refines such configurations away.
//!
//! Patches have no thickness: they fill the crack exactly and add no skirt.
//!
//! A place holds one normal: where a coarse edge of the side is cut, the fine vertex on its cut
//! half (in the same place when the density is linear along the edge) takes the coarse vertex's
//! normal, inside the side always and on its border lines where [`Transition::share_borders`]
//! says every chunk of this level around the line does the same. Where the caller cannot tell
//! (an edge of the coarse neighbour where the chunk beside this one is of its level and may face
//! nothing coarser: a straight level boundary, or a coarse chunk met only diagonally), the fine
//! and the coarse copy keep their own levels' normals, and one edge still has one normal.

use crate::mesher::{is_solid, Ctx};
use pmc_geometry::glam::{DVec2, DVec3};
use pmc_geometry::{ChunkGrid, ChunkSide};
use std::collections::HashMap;

/// A side of a chunk whose neighbour across it is one level coarser, with the density gradients
/// the coarse neighbour's mesher computes at the coarse voxels of that side.
#[derive(Clone, Copy, Debug)]
pub struct Transition<'a> {
    /// The side.
    pub side: ChunkSide,
    /// Gradients at the voxels listed by [`coarse_voxels`] for this side, in that order.
    pub gradients: &'a [DVec3],
    /// Whether the fine vertices on each of the side's four border lines take the normals of
    /// the coarse vertices in their places, as the vertices inside the side do: index `[k][e]`
    /// is the line where the side's in-plane axis `k` (the lower of its two axes first) is at
    /// its low (`e = 0`) or high (`e = 1`) end. True only where every chunk of this level
    /// holding the line does the same: where the line runs through the middle of the coarse
    /// neighbour's side, lies on a cube corner, on the shell's boundary, or on another side of
    /// this chunk that faces a coarser neighbour.
    pub share_borders: [[bool; 2]; 2],
}

/// A padded voxel index `(a, b, c)`.
type Voxel = (usize, usize, usize);

/// The plane of `side` in padded indices: its axis, its index along that axis, and the two
/// in-plane axes in increasing order.
fn plane(grid: &ChunkGrid, side: ChunkSide) -> (usize, usize, [usize; 2]) {
    let ax = side.axis();
    let at = if side.is_max() { grid.tiles + 1 } else { 1 };
    let inplane = match ax {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    };
    (ax, at, inplane)
}

/// The padded voxel at in-plane indices `(x, y)` of a plane.
fn voxel_at(ax: usize, at: usize, inplane: [usize; 2], x: usize, y: usize) -> Voxel {
    let mut v = [0usize; 3];
    v[ax] = at;
    v[inplane[0]] = x;
    v[inplane[1]] = y;
    (v[0], v[1], v[2])
}

/// The voxels of `side` that are also voxels of the one-level-coarser neighbour (every other
/// voxel of the side, starting at the chunk's corner), first in-plane axis fastest.
///
/// `grid.tiles` must be even.
pub fn coarse_voxels(grid: &ChunkGrid, side: ChunkSide) -> Vec<(usize, usize, usize)> {
    let (ax, at, inplane) = plane(grid, side);
    let m = grid.tiles / 2;
    let mut out = Vec::with_capacity((m + 1) * (m + 1));
    for q2 in 0..=m {
        for q1 in 0..=m {
            out.push(voxel_at(ax, at, inplane, 1 + 2 * q1, 1 + 2 * q2));
        }
    }
    out
}

/// A cut vertex of a patch: its mesh index and its position in the square's plane coordinates.
#[derive(Clone, Copy, Debug)]
struct Cut {
    index: u32,
    pos: DVec2,
}

/// The state of one side's patches.
struct SideState<'g> {
    ax: usize,
    at: usize,
    inplane: [usize; 2],
    gradients: &'g [DVec3],
    /// Coarse voxels per in-plane row.
    row: usize,
}

impl Ctx<'_> {
    /// Emits the transition patches of every side in `transitions`.
    pub(crate) fn emit_transitions(&mut self, transitions: &[Transition]) {
        if transitions.is_empty() || self.grid.tiles % 2 == 1 {
            return;
        }
        let mut coarse_cache: HashMap<(usize, usize), u32> = HashMap::new();
        for t in transitions {
            let (ax, at, inplane) = plane(self.grid, t.side);
            let m = self.grid.tiles / 2;
            if t.gradients.len() != (m + 1) * (m + 1) {
                debug_assert!(false, "transition gradients must match coarse_voxels");
                continue;
            }
            let st = SideState {
                ax,
                at,
                inplane,
                gradients: t.gradients,
                row: m + 1,
            };
            // Outward normal of a triangle counter-clockwise in plane coordinates, along `ax`:
            // +1 when e1 x e2 points along +ax in the right-handed (u, v, depth) index space.
            let param_sign = if ax == 1 { -1 } else { 1 };
            // The fine side (this chunk) lies towards -ax from a max side, +ax from a min side.
            let fine_sign = if t.side.is_max() { -1 } else { 1 };
            let flip = param_sign != fine_sign;
            for q2 in 0..m {
                for q1 in 0..m {
                    self.emit_square(&st, q1, q2, flip, &mut coarse_cache);
                }
            }
        }
        for t in transitions {
            self.share_seam_normals(t, &coarse_cache);
        }
    }

    /// Gives each fine vertex on a coarse line of the transition's side (a line of the plane
    /// through coarse voxels) the normal of the coarse vertex in the same place, on the side's
    /// border lines only where [`Transition::share_borders`] says so.
    ///
    /// Where a coarse edge of the side is cut, exactly one of its two fine halves is cut too,
    /// and the two cuts are the same place whenever the density is linear along the edge
    /// (along a column on every height-field terrain, and along a row wherever the terrain is
    /// locally linear): the patch holds both, the coarse one with the coarse neighbour's
    /// normal, the fine one with the fine chunk's own. The fine vertex takes the coarse normal
    /// (its raw gradient, so the two normalise to the same bits), and the place shades the same
    /// in the fine chunk, in its patch and in the coarse chunk. A vertex inside the side belongs
    /// to this chunk alone; one on a border line is shared with the other chunks of this level
    /// around the line, which do the same exactly when the caller's
    /// [`Transition::share_borders`] holds.
    fn share_seam_normals(&mut self, t: &Transition, coarse_cache: &HashMap<(usize, usize), u32>) {
        let (ax, at, inplane) = plane(self.grid, t.side);
        let m = self.grid.tiles / 2;
        let g = self.grid;
        // The voxel at in-plane offset `s` along axis `along` and `c` along the other.
        let voxel = |along: usize, s: usize, c: usize| {
            let (x, y) = if along == 0 { (s, c) } else { (c, s) };
            voxel_at(ax, at, inplane, x, y)
        };
        let solid = |v: Voxel| is_solid(self.densities[g.index(v.0, v.1, v.2)]);
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (along, &axis) in inplane.iter().enumerate() {
            let across = 1 - along;
            for q in 0..=m {
                if (q == 0 && !t.share_borders[across][0]) || (q == m && !t.share_borders[across][1]) {
                    continue;
                }
                let c = 1 + 2 * q;
                for r in 0..m {
                    let s = 1 + 2 * r;
                    let (v0, v1, v2) = (voxel(along, s, c), voxel(along, s + 1, c), voxel(along, s + 2, c));
                    let (s0, s1, s2) = (solid(v0), solid(v1), solid(v2));
                    if s0 == s2 {
                        continue;
                    }
                    let Some(&coarse) = coarse_cache.get(&(g.index(v0.0, v0.1, v0.2), axis)) else {
                        continue;
                    };
                    let half = if s0 != s1 { v0 } else { v1 };
                    if let Some(fine) = self.mesher.cached_vertex(g.index(half.0, half.1, half.2) * 3 + axis) {
                        pairs.push((fine, coarse));
                    }
                }
            }
        }
        for (fine, coarse) in pairs {
            self.out.normals[fine as usize] = self.out.normals[coarse as usize];
        }
    }

    /// The patch of coarse square `(q1, q2)` of a side.
    fn emit_square(
        &mut self,
        st: &SideState,
        q1: usize,
        q2: usize,
        flip: bool,
        cache: &mut HashMap<(usize, usize), u32>,
    ) {
        let (x0, y0) = (1 + 2 * q1, 1 + 2 * q2);
        let vox = |d1: usize, d2: usize| voxel_at(st.ax, st.at, st.inplane, x0 + d1, y0 + d2);
        let solid = |v: Voxel| is_solid(self.densities[self.grid.index(v.0, v.1, v.2)]);
        let mut s = [[false; 3]; 3];
        let mut any = false;
        let mut all = true;
        for (d1, col) in s.iter_mut().enumerate() {
            for (d2, cell) in col.iter_mut().enumerate() {
                *cell = solid(vox(d1, d2));
                any |= *cell;
                all &= *cell;
            }
        }
        if !any || all {
            return;
        }
        let mut segs: Vec<(Cut, Cut)> = Vec::with_capacity(16);
        // Coarse contour, solid on the left.
        let corners = [(0, 0), (2, 0), (2, 2), (0, 2)];
        self.square_contour(st, &s, x0, y0, corners, 2, cache, &mut segs, false);
        // Fine contours, reversed.
        for (o1, o2) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let c = [(o1, o2), (o1 + 1, o2), (o1 + 1, o2 + 1), (o1, o2 + 1)];
            self.square_contour(st, &s, x0, y0, c, 1, cache, &mut segs, true);
        }
        // Bridges along the border.
        for side in 0..4 {
            let a = corners[side];
            let b = corners[(side + 1) % 4];
            self.bridges(st, &s, x0, y0, a, b, cache, &mut segs);
        }
        self.emit_loops(&segs, flip);
    }

    /// The marching-squares contour of a square with corners `c` (counter-clockwise, in plane
    /// offsets from `(x0, y0)`, side `size`), solid on the left; reversed when `reverse`.
    #[allow(clippy::too_many_arguments)]
    fn square_contour(
        &mut self,
        st: &SideState,
        s: &[[bool; 3]; 3],
        x0: usize,
        y0: usize,
        c: [(usize, usize); 4],
        size: usize,
        cache: &mut HashMap<(usize, usize), u32>,
        segs: &mut Vec<(Cut, Cut)>,
        reverse: bool,
    ) {
        let sol = |i: usize| s[c[i % 4].0][c[i % 4].1];
        if (0..4).all(sol) || !(0..4).any(sol) {
            return;
        }
        for (end, start) in solid_runs(sol) {
            let exit = self.cut(st, s, x0, y0, c[end], c[(end + 1) % 4], size, cache);
            let entry = self.cut(st, s, x0, y0, c[(start + 3) % 4], c[start], size, cache);
            segs.push(if reverse { (entry, exit) } else { (exit, entry) });
        }
    }

    /// The cut vertex on the grid edge between plane points `p` and `q` (offsets from
    /// `(x0, y0)`, `size` apart along one in-plane axis): a fine edge (`size` 1, this chunk's)
    /// or a coarse edge (`size` 2, the coarser neighbour's).
    #[allow(clippy::too_many_arguments)]
    fn cut(
        &mut self,
        st: &SideState,
        _s: &[[bool; 3]; 3],
        x0: usize,
        y0: usize,
        p: (usize, usize),
        q: (usize, usize),
        size: usize,
        cache: &mut HashMap<(usize, usize), u32>,
    ) -> Cut {
        let (lo, hi) = if p <= q { (p, q) } else { (q, p) };
        let along = if lo.0 != hi.0 { 0 } else { 1 };
        let axis = st.inplane[along];
        let v = voxel_at(st.ax, st.at, st.inplane, x0 + lo.0, y0 + lo.1);
        let w = voxel_at(st.ax, st.at, st.inplane, x0 + hi.0, y0 + hi.1);
        let index = if size == 1 {
            self.edge_vertex(v, axis)
        } else {
            let slot = (self.grid.index(v.0, v.1, v.2), axis);
            match cache.get(&slot) {
                Some(i) => *i,
                None => {
                    let gv = st.gradients[self.coarse_slot(st, x0 + lo.0, y0 + lo.1)];
                    let gw = st.gradients[self.coarse_slot(st, x0 + hi.0, y0 + hi.1)];
                    let i = self.push_vertex(v, w, axis, gv, gw);
                    cache.insert(slot, i);
                    i
                }
            }
        };
        // Plane position: the same interpolation parameter as the vertex, from the canonical
        // first voxel.
        let (first_is_lo, t) = self.edge_parameter(v, w, axis);
        let (pl, ph) = (
            DVec2::new(lo.0 as f64, lo.1 as f64),
            DVec2::new(hi.0 as f64, hi.1 as f64),
        );
        let pos = if first_is_lo {
            pl + (ph - pl) * t
        } else {
            ph + (pl - ph) * t
        };
        Cut { index, pos }
    }

    /// The index into a side's gradients of the coarse voxel at in-plane indices `(x, y)`.
    fn coarse_slot(&self, st: &SideState, x: usize, y: usize) -> usize {
        (y - 1) / 2 * st.row + (x - 1) / 2
    }

    /// Whether `v` is the canonical first voxel of the edge `v`-`w` along `axis`, and the
    /// interpolation parameter from the canonical first voxel (as the vertex's position uses).
    pub(crate) fn edge_parameter(&self, v: Voxel, w: Voxel, axis: usize) -> (bool, f64) {
        let g = self.grid;
        let p = g.padded;
        let first_is_v = axis == 2 || g.lattice[v.1 * p + v.0].to_array() < g.lattice[w.1 * p + w.0].to_array();
        let (f, s) = if first_is_v { (v, w) } else { (w, v) };
        let df = f64::from(self.densities[g.index(f.0, f.1, f.2)]);
        let ds = f64::from(self.densities[g.index(s.0, s.1, s.2)]);
        let t = if df == ds {
            0.0
        } else {
            (df / (df - ds)).clamp(0.0, 1.0)
        };
        (first_is_v, t)
    }

    /// The bridges on the border side from corner `a` to corner `b` (counter-clockwise): the
    /// intervals where the coarse and the fine side disagree, found by walking the side's three
    /// samples in canonical order so both squares sharing it find the same intervals.
    #[allow(clippy::too_many_arguments)]
    fn bridges(
        &mut self,
        st: &SideState,
        s: &[[bool; 3]; 3],
        x0: usize,
        y0: usize,
        a: (usize, usize),
        b: (usize, usize),
        cache: &mut HashMap<(usize, usize), u32>,
        segs: &mut Vec<(Cut, Cut)>,
    ) {
        let mid = ((a.0 + b.0) / 2, (a.1 + b.1) / 2);
        let sol = |p: (usize, usize)| s[p.0][p.1];
        let (sa, sm, sb) = (sol(a), sol(mid), sol(b));
        if sa == sm && sm == sb {
            return;
        }
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        let along = if lo.0 != hi.0 { 0 } else { 1 };
        let axis = st.inplane[along];
        let v = voxel_at(st.ax, st.at, st.inplane, x0 + lo.0, y0 + lo.1);
        let w = voxel_at(st.ax, st.at, st.inplane, x0 + hi.0, y0 + hi.1);
        // Canonical first end of the line (the same for the coarse edge and both fine edges on
        // it: canonical order is monotone along a grid line).
        let (lo_first, _) = self.edge_parameter(v, w, axis);
        let (f, sec) = if lo_first { (lo, hi) } else { (hi, lo) };
        // Breakpoints at their distance from the canonical first end (in fine steps): the coarse
        // cut, then the fine cuts; ties keep that order.
        let mut points: Vec<(f64, u8, Cut)> = Vec::with_capacity(3);
        if sol(f) != sol(sec) {
            let c = self.cut(st, s, x0, y0, f, sec, 2, cache);
            let (_, t) = self.edge_parameter(v, w, axis);
            points.push((2.0 * t, 0, c));
        }
        if sol(f) != sol(mid) {
            let c = self.cut(st, s, x0, y0, f, mid, 1, cache);
            points.push((self.fine_parameter(st, x0, y0, f, mid, axis), 1, c));
        }
        if sol(mid) != sol(sec) {
            let c = self.cut(st, s, x0, y0, mid, sec, 1, cache);
            points.push((1.0 + self.fine_parameter(st, x0, y0, mid, sec, axis), 2, c));
        }
        points.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.cmp(&q.1)));
        let (mut coarse, mut fine) = (sol(f), sol(f));
        // Whether the canonical direction runs counter-clockwise around this square.
        let canonical_is_ccw = f == a;
        for pair in 0..points.len() {
            let (_, kind, cut) = points[pair];
            if pair > 0 && coarse != fine {
                let prev = points[pair - 1].2;
                let forward = coarse == canonical_is_ccw;
                segs.push(if forward { (prev, cut) } else { (cut, prev) });
            }
            if kind == 0 {
                coarse = !coarse;
            } else {
                fine = !fine;
            }
        }
    }

    /// The interpolation parameter of the fine edge from plane point `p` to `q` (adjacent),
    /// measured from `p`, which is its canonical first end.
    #[allow(clippy::too_many_arguments)]
    fn fine_parameter(
        &self,
        st: &SideState,
        x0: usize,
        y0: usize,
        p: (usize, usize),
        q: (usize, usize),
        axis: usize,
    ) -> f64 {
        let (lo, hi) = if p <= q { (p, q) } else { (q, p) };
        let v = voxel_at(st.ax, st.at, st.inplane, x0 + lo.0, y0 + lo.1);
        let w = voxel_at(st.ax, st.at, st.inplane, x0 + hi.0, y0 + hi.1);
        let (first_is_lo, t) = self.edge_parameter(v, w, axis);
        debug_assert_eq!(first_is_lo, p == lo, "canonical order is monotone along a line");
        t
    }

    /// Chains `segs` into loops and triangulates each in the plane, keeping its orientation
    /// (reversed when `flip`).
    fn emit_loops(&mut self, segs: &[(Cut, Cut)], flip: bool) {
        let mut used = vec![false; segs.len()];
        for first in 0..segs.len() {
            if used[first] {
                continue;
            }
            let mut poly: Vec<Cut> = Vec::with_capacity(8);
            let mut at = first;
            loop {
                used[at] = true;
                poly.push(segs[at].0);
                let to = segs[at].1.index;
                if to == segs[first].0.index {
                    break;
                }
                match (0..segs.len()).find(|j| !used[*j] && segs[*j].0.index == to) {
                    Some(j) => at = j,
                    None => {
                        debug_assert!(false, "transition segments must chain into loops");
                        poly.clear();
                        break;
                    }
                }
            }
            if poly.len() < 3 {
                continue;
            }
            let poly: Vec<(u32, DVec2)> = poly.iter().map(|c| (c.index, c.pos)).collect();
            for tri in ear_clip_indices(&poly) {
                let [a, b, c] = tri;
                let t = if flip { [a, c, b] } else { [a, b, c] };
                self.out.indices.extend_from_slice(&t);
            }
        }
    }
}

/// The maximal runs of solid corners of a square whose corners (counter-clockwise) are solid
/// where `sol` says so, as `(end, start)`: each run, from `start` to `end` (cyclic), is cut off by
/// one segment from the cut after `end` to the cut before `start` (marching squares, diagonally
/// opposite solid corners kept apart). `sol` takes any index and reads it modulo 4.
pub(crate) fn solid_runs(sol: impl Fn(usize) -> bool) -> Vec<(usize, usize)> {
    let mut runs = Vec::with_capacity(2);
    for end in 0..4 {
        if !sol(end) || sol(end + 1) {
            continue;
        }
        let mut start = end;
        while sol(start + 3) {
            start = (start + 3) % 4;
        }
        runs.push((end, start));
    }
    runs
}

/// Triangulates a simple polygon (either orientation) by ear clipping; the triangles keep the
/// polygon's orientation. Degenerate polygons (no ear found) are fanned.
pub(crate) fn ear_clip_indices(poly: &[(u32, DVec2)]) -> Vec<[u32; 3]> {
    ear_clip_with(poly, false)
}

/// [`ear_clip_indices`], refusing also an ear with another vertex on its border (`closed`):
/// polygons with runs of collinear vertices (a cap's side along a chunk edge) then never leave
/// a remainder of zero area to fan.
pub(crate) fn ear_clip_closed(poly: &[(u32, DVec2)]) -> Vec<[u32; 3]> {
    ear_clip_with(poly, true)
}

fn ear_clip_with(poly: &[(u32, DVec2)], closed: bool) -> Vec<[u32; 3]> {
    let area: f64 = (0..poly.len())
        .map(|i| {
            let (p, q) = (poly[i].1, poly[(i + 1) % poly.len()].1);
            p.perp_dot(q)
        })
        .sum();
    let sign = if area < 0.0 { -1.0 } else { 1.0 };
    let mut idx: Vec<usize> = (0..poly.len()).collect();
    let mut out = Vec::with_capacity(poly.len() - 2);
    while idx.len() > 3 {
        let n = idx.len();
        let ear = (0..n).find(|&i| {
            let (a, b, c) = (poly[idx[(i + n - 1) % n]].1, poly[idx[i]].1, poly[idx[(i + 1) % n]].1);
            if (b - a).perp_dot(c - b) * sign <= 0.0 {
                return false;
            }
            idx.iter().enumerate().all(|(j, &k)| {
                if j == i || j == (i + n - 1) % n || j == (i + 1) % n {
                    return true;
                }
                let p = poly[k].1;
                if closed {
                    if p == a || p == b || p == c {
                        return true;
                    }
                    let inside = |u: DVec2, v: DVec2| (v - u).perp_dot(p - u) * sign >= 0.0;
                    return !(inside(a, b) && inside(b, c) && inside(c, a));
                }
                let inside = |u: DVec2, v: DVec2| (v - u).perp_dot(p - u) * sign > 0.0;
                !(inside(a, b) && inside(b, c) && inside(c, a))
            })
        });
        match ear {
            Some(i) => {
                let n = idx.len();
                out.push([poly[idx[(i + n - 1) % n]].0, poly[idx[i]].0, poly[idx[(i + 1) % n]].0]);
                idx.remove(i);
            }
            None => {
                for i in 1..idx.len() - 1 {
                    out.push([poly[idx[0]].0, poly[idx[i]].0, poly[idx[i + 1]].0]);
                }
                return out;
            }
        }
    }
    out.push([poly[idx[0]].0, poly[idx[1]].0, poly[idx[2]].0]);
    out
}
