//! Closed chunks: caps on the six sides, so one chunk's mesh is the whole boundary of its solid.
//!
//! # Why
//!
//! A client that picks every chunk's level on its own (a 3D Tiles viewer has no 2:1 balance and
//! no seam masks) may put any coarser chunk beside any finer one, and their surfaces then meet
//! the shared side along two different curves. Transition patches ([`crate::transition`]) close
//! such a crack only for a neighbour one level coarser that the fine chunk knows of. A cap closes
//! it for every neighbour at once: each chunk adds, on each of its six sides, the part of the
//! side that is solid, so its mesh bounds a closed solid. A ray that starts in the air, outside
//! every chunk's solid, first meets a surface where it enters some solid: a front face, surface
//! or cap, whatever the levels beside each other. Through a crack the eye sees the higher
//! chunk's cap (front-facing, coloured like the rock at its border), never the inside of a
//! solid. Where two chunks of one level meet, their caps coincide back to back inside the solid,
//! hidden behind the surfaces.
//!
//! # How
//!
//! On a side's plane the solid region is what marching squares says it is, by the rule of
//! [`crate::tables`] (diagonally opposite solid corners are kept apart), which is the rule the
//! mesher's cubes cut that plane with: the region's curved border is exactly the mesh's border
//! there, vertex for vertex. The plane is cut into strips one cell high; in a strip every solid
//! component touches the strip's lines (each component of marching squares holds a sample, and
//! the samples lie on the lines), so each is a simple polygon with no hole, ear-clipped in the
//! plane. A strip's polygons are bounded by the cell contours (solid on the left), by the solid
//! intervals of its two lines, and by its two ends. Every voxel on the chunk's twelve edges is a
//! vertex (the strips of one side end there, and the side beyond the edge must use the same
//! vertices); on a line inside the side, only its cuts and its ends are. So the caps of two
//! sides meeting at a chunk edge share that edge's segments in opposite directions, and the
//! caps meet the mesh along its border edges: the chunk's mesh is a closed 2-manifold when
//! vertices are identified by edge key (a voxel vertex's key is the voxel's key twice).
//!
//! A voxel vertex takes the density gradient at its voxel for its normal and the voxel as both
//! ends of its grid edge ([`crate::ChunkMesh::vertex_edges`]), so a shader reads the voxel's
//! own column there.

use crate::mesher::{is_solid, Ctx};
use crate::transition::{ear_clip_closed, solid_runs};
use pmc_geometry::glam::DVec2;
use pmc_geometry::{ChunkSide, EdgeKey};
use std::collections::HashMap;

/// A padded voxel index `(a, b, c)`.
type Voxel = (usize, usize, usize);

/// A polygon vertex: its mesh index and its place in the side's plane coordinates.
#[derive(Clone, Copy, Debug)]
struct Point {
    index: u32,
    pos: DVec2,
}

/// One side's plane: its axis, its padded index along it, and its two in-plane axes in
/// increasing order.
#[derive(Clone, Copy)]
struct Plane {
    ax: usize,
    at: usize,
    inplane: [usize; 2],
}

impl Plane {
    /// The plane of `side`. On the four sides across the face (`u` or `v` constant) the first
    /// in-plane axis is depth, so a strip (one cell along the second axis) is a column of cells
    /// between two radial lines: a plane through the planet's centre, where the cap lies flat and
    /// the mesh's border edges lie too. On the inner and outer sides (depth constant) the axes
    /// are `u` then `v`.
    fn of(tiles: usize, side: ChunkSide) -> Plane {
        let ax = side.axis();
        let at = if side.is_max() { tiles + 1 } else { 1 };
        let inplane = match ax {
            0 => [2, 1],
            1 => [2, 0],
            _ => [0, 1],
        };
        Plane { ax, at, inplane }
    }

    /// +1 when a triangle counter-clockwise in plane coordinates faces `+ax` in the right-handed
    /// `(u, v, depth)` index space, else -1: the sign of `e[inplane[0]] x e[inplane[1]] . e[ax]`.
    fn param_sign(&self) -> i32 {
        // (ax, first, second) is an even permutation of (0, 1, 2) exactly when it is cyclic.
        if (self.ax + 1) % 3 == self.inplane[0] && (self.ax + 2) % 3 == self.inplane[1] {
            1
        } else {
            -1
        }
    }

    /// The padded voxel at in-plane indices `(x, y)`.
    fn voxel(&self, x: usize, y: usize) -> Voxel {
        let mut v = [0usize; 3];
        v[self.ax] = self.at;
        v[self.inplane[0]] = x;
        v[self.inplane[1]] = y;
        (v[0], v[1], v[2])
    }
}

impl Ctx<'_> {
    /// Emits the caps of all six sides (see the module documentation).
    pub(crate) fn emit_caps(&mut self) {
        let mut voxels: HashMap<usize, u32> = HashMap::new();
        for side in ChunkSide::ALL {
            self.emit_side_cap(side, &mut voxels);
        }
    }

    fn solid_at(&self, v: Voxel) -> bool {
        is_solid(self.densities[self.grid.index(v.0, v.1, v.2)])
    }

    /// The vertex at a voxel of a chunk edge (created once per chunk).
    fn voxel_vertex(&mut self, v: Voxel, voxels: &mut HashMap<usize, u32>) -> u32 {
        let g = self.grid;
        let flat = g.index(v.0, v.1, v.2);
        if let Some(&i) = voxels.get(&flat) {
            return i;
        }
        let grad = self.gradient(v);
        let key = g.voxel_key(v.0, v.1, v.2);
        let idx = self.push_raw(
            g.position(v.0, v.1, v.2),
            grad,
            EdgeKey::new(key, key),
            [flat as u32; 2],
        );
        voxels.insert(flat, idx);
        idx
    }

    /// The cut on the grid edge between plane points `p` and `q` (adjacent), with its place.
    fn plane_cut(&mut self, pl: Plane, p: (usize, usize), q: (usize, usize)) -> Point {
        let (lo, hi) = if p <= q { (p, q) } else { (q, p) };
        let along = if lo.0 != hi.0 { 0 } else { 1 };
        let axis = pl.inplane[along];
        let (v, w) = (pl.voxel(lo.0, lo.1), pl.voxel(hi.0, hi.1));
        // The grid edge runs from the voxel with the lower index along its axis.
        let (v, w) = if v < w { (v, w) } else { (w, v) };
        let index = self.edge_vertex(v, axis);
        let (first_is_lo, t) = self.edge_parameter(v, w, axis);
        // A cut at an end of its edge (a sample exactly 0 there, which is air) would coincide
        // with the cuts of the other edges meeting at that voxel: kept a hair inside its own
        // edge in the plane, the polygon stays simple. Only the triangulation reads this place.
        let t = t.clamp(1e-6, 1.0 - 1e-6);
        let (a, b) = (
            DVec2::new(lo.0 as f64, lo.1 as f64),
            DVec2::new(hi.0 as f64, hi.1 as f64),
        );
        let pos = if first_is_lo { a + (b - a) * t } else { b + (a - b) * t };
        Point { index, pos }
    }

    /// The cap of one side, strip by strip.
    fn emit_side_cap(&mut self, side: ChunkSide, voxels: &mut HashMap<usize, u32>) {
        let t = self.grid.tiles;
        let pl = Plane::of(t, side);
        let solid = |ctx: &Self, x: usize, y: usize| ctx.solid_at(pl.voxel(x, y));
        // Nothing to do on a side with no solid voxel.
        if !(1..=t + 1).any(|y| (1..=t + 1).any(|x| solid(self, x, y))) {
            return;
        }
        let param_sign = pl.param_sign();
        let outward = if side.is_max() { 1 } else { -1 };
        let flip = param_sign != outward;
        let mut segs: Vec<(Point, Point)> = Vec::new();
        for y in 1..=t {
            segs.clear();
            // Cell contours, solid on the left.
            for x in 1..=t {
                let c = [(x, y), (x + 1, y), (x + 1, y + 1), (x, y + 1)];
                let corners = c.map(|(x, y)| solid(self, x, y));
                let sol = |i: usize| corners[i % 4];
                if (0..4).all(sol) || !(0..4).any(sol) {
                    continue;
                }
                for (end, start) in solid_runs(sol) {
                    let exit = self.plane_cut(pl, c[end], c[(end + 1) % 4]);
                    let entry = self.plane_cut(pl, c[(start + 3) % 4], c[start]);
                    segs.push((exit, entry));
                }
            }
            // The strip's lower line left to right, its upper line right to left: every voxel
            // on a chunk edge is a breakpoint, elsewhere only the ends.
            self.line_segments(pl, y, false, y == 1, voxels, &mut segs);
            self.line_segments(pl, y + 1, true, y + 1 == t + 1, voxels, &mut segs);
            // The strip's ends: the right one upwards, the left one downwards.
            for (x, up) in [(t + 1, true), (1, false)] {
                let (a, b) = if up { ((x, y), (x, y + 1)) } else { ((x, y + 1), (x, y)) };
                let (sa, sb) = (solid(self, a.0, a.1), solid(self, b.0, b.1));
                let point = |ctx: &mut Self, p: (usize, usize), vx: &mut HashMap<usize, u32>| Point {
                    index: ctx.voxel_vertex(pl.voxel(p.0, p.1), vx),
                    pos: DVec2::new(p.0 as f64, p.1 as f64),
                };
                match (sa, sb) {
                    (true, true) => {
                        let (pa, pb) = (point(self, a, voxels), point(self, b, voxels));
                        segs.push((pa, pb));
                    }
                    (true, false) => {
                        let (pa, cut) = (point(self, a, voxels), self.plane_cut(pl, a, b));
                        segs.push((pa, cut));
                    }
                    (false, true) => {
                        let (cut, pb) = (self.plane_cut(pl, a, b), point(self, b, voxels));
                        segs.push((cut, pb));
                    }
                    (false, false) => {}
                }
            }
            self.emit_cap_loops(&segs, flip);
        }
    }

    /// The solid intervals of the side's line `y` as segments: left to right, or right to left
    /// when `reverse`. Breakpoints are the cuts on the line and, where solid, its two ends, or
    /// every voxel when `all_voxels` (a chunk edge).
    fn line_segments(
        &mut self,
        pl: Plane,
        y: usize,
        reverse: bool,
        all_voxels: bool,
        voxels: &mut HashMap<usize, u32>,
        segs: &mut Vec<(Point, Point)>,
    ) {
        let t = self.grid.tiles;
        let mut points: Vec<Point> = Vec::new();
        // Walk left to right, collecting breakpoints of solid runs; each run gives a chain.
        let mut chains: Vec<Vec<Point>> = Vec::new();
        for x in 1..=t + 1 {
            let s = self.solid_at(pl.voxel(x, y));
            let prev = x > 1 && self.solid_at(pl.voxel(x - 1, y));
            if s && !prev && x > 1 {
                // A run starts inside the line: its cut.
                points.push(self.plane_cut(pl, (x - 1, y), (x, y)));
            }
            if s && (all_voxels || x == 1 || x == t + 1) {
                points.push(Point {
                    index: self.voxel_vertex(pl.voxel(x, y), voxels),
                    pos: DVec2::new(x as f64, y as f64),
                });
            }
            if s && x < t + 1 && !self.solid_at(pl.voxel(x + 1, y)) {
                // The run ends inside the line: its cut.
                points.push(self.plane_cut(pl, (x, y), (x + 1, y)));
                chains.push(std::mem::take(&mut points));
            }
        }
        if !points.is_empty() {
            chains.push(points);
        }
        for chain in chains {
            for pair in chain.windows(2) {
                segs.push(if reverse {
                    (pair[1], pair[0])
                } else {
                    (pair[0], pair[1])
                });
            }
        }
    }

    /// Chains a strip's segments into loops and triangulates each (a simple polygon), facing out
    /// of the chunk.
    fn emit_cap_loops(&mut self, segs: &[(Point, Point)], flip: bool) {
        let mut next: HashMap<u32, usize> = HashMap::with_capacity(segs.len());
        for (i, s) in segs.iter().enumerate() {
            let clash = next.insert(s.0.index, i);
            debug_assert!(clash.is_none(), "one cap segment leaves each vertex");
        }
        let mut used = vec![false; segs.len()];
        let mut poly: Vec<(u32, DVec2)> = Vec::new();
        for first in 0..segs.len() {
            if used[first] {
                continue;
            }
            poly.clear();
            let mut at = first;
            let closed = loop {
                used[at] = true;
                poly.push((segs[at].0.index, segs[at].0.pos));
                let to = segs[at].1.index;
                if to == segs[first].0.index {
                    break true;
                }
                match next.get(&to) {
                    Some(&j) if !used[j] => at = j,
                    _ => break false,
                }
            };
            debug_assert!(closed, "cap segments must chain into loops");
            if !closed || poly.len() < 3 {
                continue;
            }
            for [a, b, c] in ear_clip_closed(&poly) {
                let tri = if flip { [a, c, b] } else { [a, b, c] };
                self.out.indices.extend_from_slice(&tri);
            }
        }
    }
}
