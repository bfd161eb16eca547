//! Voxel columns of the whole planet: one per point of the cube-surface lattice, numbered, with
//! their neighbours across chunk borders, face edges and cube corners.
//!
//! A column is a canonical lattice point (see [`Layout::lattice`]): points on a face edge or a
//! cube corner belong to two or three faces but are one column. Its four neighbours are the
//! lattice points one grid step away along the axes of every face that holds it; on a face edge
//! the step off one face is the step onto the other (Algorithm 1 unfolds the faces the same way),
//! and a cube corner has three neighbours, one along each edge.

use pmc_geometry::glam::{DVec3, IVec3};
use pmc_geometry::{sphere_to_face_uv, Face, Layout};

/// The columns of a layout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Columns {
    layout: Layout,
    /// Grid steps along a face side, `N = n_c n_t`.
    n: i64,
}

/// A column's canonical place: the first face of [`Face::ALL`] that holds it, and its grid
/// indices `(i, j)` on that face, each in `0..=N`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ColumnPlace {
    /// The face.
    pub face: Face,
    /// Grid index along the face's `u` axis.
    pub i: i64,
    /// Grid index along the face's `v` axis.
    pub j: i64,
}

impl Columns {
    /// The columns of `layout`.
    pub fn new(layout: &Layout) -> Columns {
        Columns {
            layout: *layout,
            n: layout.face_tiles(),
        }
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Grid steps along a face side, `N`.
    pub fn face_tiles(&self) -> i64 {
        self.n
    }

    /// Size of the column index space: `6 (N + 1)^2` (edge and corner columns use the slot of
    /// their canonical face; the other slots stay unused).
    pub fn index_count(&self) -> usize {
        6 * ((self.n + 1) * (self.n + 1)) as usize
    }

    /// The index of the canonical column at `place`.
    pub fn index_of(&self, place: ColumnPlace) -> u32 {
        let side = self.n + 1;
        (place.face.index() as i64 * side * side + place.j * side + place.i) as u32
    }

    /// The place of column `index` (which must be canonical: from [`Columns::index_of`]).
    pub fn place_of(&self, index: u32) -> ColumnPlace {
        let side = self.n + 1;
        let i64i = i64::from(index);
        let face = Face::from_index((i64i / (side * side)) as usize).unwrap_or(Face::Top);
        let rest = i64i % (side * side);
        ColumnPlace {
            face,
            i: rest % side,
            j: rest / side,
        }
    }

    /// The canonical place of a lattice point (which must lie on the cube surface).
    pub fn place_of_lattice(&self, p: IVec3) -> ColumnPlace {
        let n = self.n as i32;
        let face = Face::ALL
            .into_iter()
            .find(|f| p.dot(f.frame().n) == n)
            .unwrap_or(Face::Top);
        let fr = face.frame();
        ColumnPlace {
            face,
            i: i64::from((p.dot(fr.u) + n) / 2),
            j: i64::from((p.dot(fr.v) + n) / 2),
        }
    }

    /// The lattice point of a place.
    pub fn lattice(&self, place: ColumnPlace) -> IVec3 {
        // In range by construction, so `lattice` cannot fail.
        self.layout.lattice(place.face, place.i, place.j).unwrap_or(IVec3::ZERO)
    }

    /// The index of the column at lattice point `p`.
    pub fn index_of_lattice(&self, p: IVec3) -> u32 {
        self.index_of(self.place_of_lattice(p))
    }

    /// Whether `place` is the canonical place of its column (edge and corner columns also appear
    /// on faces later in [`Face::ALL`]).
    pub fn is_canonical(&self, place: ColumnPlace) -> bool {
        self.place_of_lattice(self.lattice(place)) == place
    }

    /// The unit direction of column `index`: exactly the direction the mesher samples.
    pub fn direction(&self, index: u32) -> DVec3 {
        self.layout.lattice_direction(self.lattice(self.place_of(index)))
    }

    /// The neighbours of column `index` (4; 3 at a cube corner), as column indices, in a fixed
    /// order.
    pub fn neighbours(&self, index: u32) -> Neighbours {
        let places = self.neighbour_places(self.place_of(index));
        let mut out = Neighbours { list: [0; 4], len: 0 };
        for (slot, place) in out.list.iter_mut().zip(places.iter()) {
            *slot = self.index_of(*place);
        }
        out.len = places.len();
        out
    }

    /// The canonical places of the neighbours of the column at canonical place `place` (4; 3 at
    /// a cube corner), in the order of [`Columns::neighbours`]. Unlike the column indices, places
    /// exist for layouts of any size.
    pub fn neighbour_places(&self, place: ColumnPlace) -> NeighbourPlaces {
        let mut out = NeighbourPlaces {
            list: [place; 4],
            len: 0,
        };
        let n = self.n;
        if place.i > 1 && place.i < n - 1 && place.j > 1 && place.j < n - 1 {
            // Inside a face, neighbours included: the lattice steps are the face's own grid
            // steps, in the order of the general case (+u, -u, +v, -v).
            let ColumnPlace { face, i, j } = place;
            out.list = [
                ColumnPlace { face, i: i + 1, j },
                ColumnPlace { face, i: i - 1, j },
                ColumnPlace { face, i, j: j + 1 },
                ColumnPlace { face, i, j: j - 1 },
            ];
            out.len = 4;
            return out;
        }
        let p = self.lattice(place);
        let n = n as i32;
        for face in Face::ALL {
            let fr = face.frame();
            if p.dot(fr.n) != n {
                continue;
            }
            for d in [fr.u, -fr.u, fr.v, -fr.v] {
                let q = p + d * 2;
                if q.dot(fr.u).abs() > n || q.dot(fr.v).abs() > n {
                    continue;
                }
                let qp = self.place_of_lattice(q);
                if !out.list[..out.len].contains(&qp) {
                    out.list[out.len] = qp;
                    out.len += 1;
                }
            }
        }
        out
    }

    /// The unit direction of the column at `place`: exactly the direction the mesher samples.
    pub fn place_direction(&self, place: ColumnPlace) -> DVec3 {
        self.layout.lattice_direction(self.lattice(place))
    }

    /// The canonical place of the column nearest to direction `dir` (any non-zero vector), or
    /// `None` for the zero or a non-finite vector.
    pub fn nearest_place(&self, dir: DVec3) -> Option<ColumnPlace> {
        let (face, u, v) = sphere_to_face_uv(dir)?;
        let n = self.n as f64;
        let grid = |x: f64| ((x + 1.0) * 0.5 * n).round().clamp(0.0, n) as i64;
        let place = ColumnPlace {
            face,
            i: grid(u),
            j: grid(v),
        };
        Some(self.place_of_lattice(self.lattice(place)))
    }

    /// A lower bound on the chord between the unit directions of any two neighbouring columns:
    /// `2 / (sqrt(3) N)`, less one part in a million for rounding. Eq. (1) packs the grid densest
    /// along the middle of each face edge, where a step along the edge spans a chord of
    /// `2 / (sqrt(3) N)` as `N` grows (and a little more for small `N`); a test checks every
    /// step of small layouts and steps all over the Earth's.
    pub fn min_step_chord(&self) -> f64 {
        2.0 / (3f64.sqrt() * self.n as f64) * (1.0 - 1e-6)
    }

    /// A lower bound on the chord between the unit directions of neighbouring columns whose
    /// lattice points both lie within `2 reach` of lattice point `centre` along every axis (so
    /// every pair of neighbours within `reach` steps of it), for heuristics that look near one
    /// place: there the grid is close to uniform and the bound close to the chords themselves.
    ///
    /// On each face the chord of a step along `u` grows with the distance of the step's middle
    /// from the face's centre line across `u` and shrinks with the distance of its row from the
    /// centre line along `u` (and likewise along `v`; Eq. (1) is symmetric in `u` and `v` and the
    /// faces are congruent), so over the rectangle of a face that the box covers the shortest
    /// step is the one nearest the middle of the rectangle's columns and in its outermost row. A
    /// test checks this on every step of small layouts; rounding is covered by one part in
    /// 10^9. Never below [`Columns::min_step_chord`].
    pub fn min_step_chord_near(&self, centre: IVec3, reach: i64) -> f64 {
        let n = self.n;
        let (lo, hi) = (centre.as_i64vec3() - 2 * reach, centre.as_i64vec3() + 2 * reach);
        // The range of `p . axis` over the box, for a signed unit axis.
        let range = |axis: IVec3| -> (i64, i64) {
            let a = axis.as_i64vec3();
            let (x, y) = (lo.dot(a), hi.dot(a));
            (x.min(y), x.max(y))
        };
        let index =
            |(a, b): (i64, i64)| -> (i64, i64) { ((a + n + 1).div_euclid(2).max(0), (b + n).div_euclid(2).min(n)) };
        let chord = |face: Face, (i, j): (i64, i64), (k, l): (i64, i64)| -> f64 {
            let d = |i, j| {
                self.layout
                    .lattice(face, i, j)
                    .map(|p| self.layout.lattice_direction(p))
            };
            match (d(i, j), d(k, l)) {
                (Some(a), Some(b)) => (a - b).length(),
                _ => f64::INFINITY,
            }
        };
        // Step starts in `a..=b - 1` nearest the middle, `(N - 1) / 2`.
        let middle = |a: i64, b: i64| [(n - 1).div_euclid(2).clamp(a, b - 1), n.div_euclid(2).clamp(a, b - 1)];
        let mut best = f64::INFINITY;
        for face in Face::ALL {
            let fr = face.frame();
            let (a, b) = range(fr.n);
            if a > n || b < n {
                continue;
            }
            let (ia, ib) = index(range(fr.u));
            let (ja, jb) = index(range(fr.v));
            if ia > ib || ja > jb {
                continue;
            }
            if ib > ia {
                for i in middle(ia, ib) {
                    for j in [ja, jb] {
                        best = best.min(chord(face, (i, j), (i + 1, j)));
                    }
                }
            }
            if jb > ja {
                for j in middle(ja, jb) {
                    for i in [ia, ib] {
                        best = best.min(chord(face, (i, j), (i, j + 1)));
                    }
                }
            }
        }
        (best * (1.0 - 1e-9)).max(self.min_step_chord())
    }

    /// The number of steps any walk from lattice point `a` to lattice point `b` takes at least:
    /// each step moves one lattice coordinate by 2, so half the L1 distance between them.
    pub fn min_steps(a: IVec3, b: IVec3) -> i64 {
        let d = (a.as_i64vec3() - b.as_i64vec3()).abs();
        (d.x + d.y + d.z) / 2
    }

    /// The column nearest to direction `dir` (any non-zero vector), or `None` for the zero or a
    /// non-finite vector.
    pub fn nearest(&self, dir: DVec3) -> Option<u32> {
        Some(self.index_of(self.nearest_place(dir)?))
    }
}

/// Up to four neighbouring column places.
#[derive(Clone, Copy, Debug)]
pub struct NeighbourPlaces {
    list: [ColumnPlace; 4],
    len: usize,
}

impl std::ops::Deref for NeighbourPlaces {
    type Target = [ColumnPlace];
    fn deref(&self) -> &[ColumnPlace] {
        &self.list[..self.len]
    }
}

/// Up to four neighbouring columns.
#[derive(Clone, Copy, Debug)]
pub struct Neighbours {
    list: [u32; 4],
    len: usize,
}

impl Neighbours {
    /// Four neighbours.
    pub(crate) fn of(list: [u32; 4]) -> Neighbours {
        Neighbours { list, len: 4 }
    }
}

impl std::ops::Deref for Neighbours {
    type Target = [u32];
    fn deref(&self) -> &[u32] {
        &self.list[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Columns {
        Columns::new(&Layout::new(2, 4, 100.0, 2.0, 1).unwrap())
    }

    #[test]
    fn every_column_has_four_neighbours_but_the_eight_corners_three_and_the_relation_is_symmetric() {
        let c = small();
        let n = c.face_tiles();
        let mut columns = 0;
        let mut corners = 0;
        for face in Face::ALL {
            for j in 0..=n {
                for i in 0..=n {
                    let place = ColumnPlace { face, i, j };
                    if !c.is_canonical(place) {
                        continue;
                    }
                    columns += 1;
                    let me = c.index_of(place);
                    assert_eq!(c.place_of(me), place);
                    let nb = c.neighbours(me);
                    if nb.len() == 3 {
                        corners += 1;
                    } else {
                        assert_eq!(nb.len(), 4, "{place:?}");
                    }
                    for q in nb.iter() {
                        assert!(c.neighbours(*q).contains(&me), "{place:?} -> {:?}", c.place_of(*q));
                        // Neighbours are one grid step apart: close in direction.
                        let angle = c.direction(me).angle_between(c.direction(*q));
                        assert!(angle > 0.0 && angle < 0.4, "{angle}");
                    }
                }
            }
        }
        // 6 N^2 + 2 distinct lattice points on the cube surface.
        assert_eq!(columns, 6 * n * n + 2);
        assert_eq!(corners, 8);
    }

    /// Every step of the layout: (lattice points, chord).
    fn all_steps(c: &Columns) -> Vec<(IVec3, IVec3, f64)> {
        let mut out = Vec::new();
        let n = c.face_tiles();
        for face in Face::ALL {
            for j in 0..=n {
                for i in 0..=n {
                    let place = ColumnPlace { face, i, j };
                    if !c.is_canonical(place) {
                        continue;
                    }
                    for q in c.neighbour_places(place).iter() {
                        let chord = (c.place_direction(place) - c.place_direction(*q)).length();
                        out.push((c.lattice(place), c.lattice(*q), chord));
                    }
                }
            }
        }
        out
    }

    #[test]
    fn no_step_is_shorter_than_the_chord_bounds() {
        for (n_c, n_t) in [(1, 1), (1, 2), (1, 3), (2, 4), (3, 5), (4, 8), (5, 7)] {
            let c = Columns::new(&Layout::new(n_c, n_t, 100.0, 1.0, 1).unwrap());
            let steps = all_steps(&c);
            let shortest = steps.iter().map(|s| s.2).fold(f64::INFINITY, f64::min);
            assert!(shortest >= c.min_step_chord(), "N = {}", c.face_tiles());
            assert!(
                shortest < c.min_step_chord() * 1.06,
                "the bound is close: N = {}",
                c.face_tiles()
            );
            // Boxes around every column, of every reach.
            let n = c.face_tiles();
            for (centre, _, _) in steps.iter().step_by((steps.len() / 150).max(1)) {
                for reach in [0, 1, 2, 3, n / 2, n] {
                    let bound = c.min_step_chord_near(*centre, reach);
                    let inside = |p: &IVec3| (*p - *centre).abs().max_element() as i64 <= 2 * reach;
                    let local = steps
                        .iter()
                        .filter(|(a, b, _)| inside(a) && inside(b))
                        .map(|s| s.2)
                        .fold(f64::INFINITY, f64::min);
                    assert!(bound <= local, "N = {n}, {centre}, reach {reach}: {bound} > {local}");
                }
            }
        }
    }

    #[test]
    fn on_the_earth_steps_are_no_shorter_than_the_bounds_and_the_near_bound_is_tight() {
        let earth = Columns::new(&Layout::new(1 << 18, 32, 6_371_000.0 - 16_384.0, 1.0, 1 << 10).unwrap());
        let n = earth.face_tiles();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |m: i64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m as u64) as i64
        };
        for k in 0..4000 {
            let face = Face::ALL[next(6) as usize];
            // Half of them on or next to an edge, where the grid is densest.
            let (i, j) = if k % 2 == 0 {
                (next(n + 1), [0, 1, n - 1, n][next(4) as usize])
            } else {
                (next(n + 1), next(n + 1))
            };
            let place = c_place(&earth, face, i, j);
            let centre = earth.lattice(place);
            let near = earth.min_step_chord_near(centre, 20_000);
            let mut shortest = f64::INFINITY;
            for q in earth.neighbour_places(place).iter() {
                let chord = (earth.place_direction(place) - earth.place_direction(*q)).length();
                assert!(chord >= earth.min_step_chord(), "{place:?}");
                assert!(chord >= near, "{place:?}: {chord} < {near}");
                shortest = shortest.min(chord);
            }
            // 20 000 steps are a quarter of a percent of a face side: the bound is within 1% of
            // the shortest step here.
            assert!(near > 0.99 * shortest, "{place:?}: {near} vs {shortest}");
        }
    }

    fn c_place(c: &Columns, face: Face, i: i64, j: i64) -> ColumnPlace {
        c.place_of_lattice(c.lattice(ColumnPlace { face, i, j }))
    }

    #[test]
    fn nearest_finds_the_column_of_its_own_direction() {
        let c = small();
        for index in 0..c.index_count() as u32 {
            if !c.is_canonical(c.place_of(index)) {
                continue;
            }
            assert_eq!(c.nearest(c.direction(index) * 7.0), Some(index));
        }
        assert_eq!(c.nearest(DVec3::ZERO), None);
        assert_eq!(c.nearest(DVec3::new(f64::NAN, 1.0, 0.0)), None);
    }
}
