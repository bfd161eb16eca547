//! The rules of Fig. 11, shared by the whole-planet grid and the lazy grid: which voxels of a
//! column are floors, and when the agent can step from a floor to a floor of a neighbouring
//! column. Both grids read a column through a [`ColumnView`] of the layers they sampled, so the
//! two cannot disagree on a step they both see.

use crate::agent::Agent;
use crate::grid::Node;
use pmc_geometry::glam::DVec3;

/// The occupancy of one column over the layers `base..base + len` that were sampled; every layer
/// below them counts as filled and every layer above them as unfilled.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ColumnView<'a> {
    /// The first layer sampled.
    pub base: i64,
    /// How many layers were sampled.
    pub len: i64,
    /// One bit per layer sampled, layer `base + b` in bit `b % 64` of word `b / 64`.
    pub words: &'a [u64],
}

impl ColumnView<'_> {
    /// Whether voxel `layer` is filled.
    #[inline]
    pub fn filled(&self, layer: i64) -> bool {
        let b = layer - self.base;
        if b < 0 {
            return true;
        }
        if b >= self.len {
            return false;
        }
        let b = b as usize;
        b / 64 < self.words.len() && self.words[b / 64] & (1 << (b % 64)) != 0
    }

    /// Whether layers `lo..=hi` are all unfilled (true for an empty range).
    #[inline]
    pub fn air(&self, lo: i64, hi: i64) -> bool {
        (lo..=hi).all(|k| !self.filled(k))
    }
}

/// An agent's limits in layers, and its slope limit, for one layout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rules {
    /// The agent.
    pub agent: Agent,
    /// Clearance in voxels above a floor (at least 1).
    pub clearance: i64,
    /// Layers a step may climb at most (the metre limit, rounded up, plus one).
    pub scan_up: i64,
    /// Layers a step may drop at most (likewise).
    pub scan_down: i64,
    /// `tan(max_slope)^2` (infinite at 90 degrees).
    pub slope2: f64,
}

impl Rules {
    /// The rules of `agent` (already validated) on layers `l_d` metres apart.
    pub fn new(agent: Agent, l_d: f64) -> Rules {
        let voxels = |m: f64| (m / l_d).ceil().max(0.0) as i64;
        Rules {
            agent,
            clearance: voxels(agent.clearance).max(1),
            scan_up: voxels(agent.step_up) + 1,
            scan_down: voxels(agent.step_down) + 1,
            slope2: if agent.max_slope >= 90.0 {
                f64::INFINITY
            } else {
                agent.max_slope.to_radians().tan().powi(2)
            },
        }
    }

    /// How far above a floor any check of these rules reads its column: the clearance over the
    /// highest floor a step from or to it can reach.
    pub fn reach_above(&self) -> i64 {
        self.scan_up.max(self.scan_down) + self.clearance
    }

    /// Applies the shell contract to the raw sample of layer `k` of a shell `depth` layers deep:
    /// layer 0 (and below) solid, layer `depth` (and above) air, NaN air.
    #[inline]
    pub fn contract(k: i64, depth: i64, raw: f32) -> f32 {
        if k <= 0 {
            if raw > 0.0 {
                raw
            } else {
                1.0
            }
        } else if raw.is_nan() || (k >= depth && raw > 0.0) {
            -1.0
        } else {
            raw
        }
    }

    /// The occupancy bits and the floors of one column from its samples `d` of layers
    /// `base..base + d.len()` (shell contract applied), layer `k` at radius `radius(k)`. Words
    /// are appended to `words` (`ceil(len / 64)` of them) and floors to `nodes`, lowest first:
    /// every filled layer `k` with `k + 1` sampled and unfilled whose clearance is air (layers
    /// above the samples count as air), its surface point where the density crosses zero
    /// between `k` and `k + 1`. The samples must not be NaN ([`Rules::contract`] maps NaN to
    /// air).
    pub fn column(
        &self,
        base: i64,
        d: &[f32],
        radius: impl Fn(i64) -> f64,
        words: &mut Vec<u64>,
        nodes: &mut Vec<Node>,
    ) {
        let at = words.len();
        for chunk in d.chunks(64) {
            let mut bits = 0u64;
            for (b, v) in chunk.iter().enumerate() {
                bits |= u64::from(*v > 0.0) << b;
            }
            words.push(bits);
        }
        let view = ColumnView {
            base,
            len: d.len() as i64,
            words: &words[at..],
        };
        // Floors: a filled layer under an unfilled one (the samples are never NaN: the contract
        // maps NaN to air), found word by word from the bits.
        for (wi, w) in view.words.iter().enumerate() {
            let next = view.words.get(wi + 1).map_or(0, |n| n & 1);
            let mut floors = w & !((w >> 1) | (next << 63));
            while floors != 0 {
                let b = wi * 64 + floors.trailing_zeros() as usize;
                floors &= floors - 1;
                let k = base + b as i64;
                if b + 1 < d.len() && view.air(k + 1, k + self.clearance) {
                    let (a, c) = (f64::from(d[b]), f64::from(d[b + 1]));
                    let t = a / (a - c);
                    let (r0, r1) = (radius(k), radius(k + 1));
                    nodes.push(Node {
                        layer: k as u32,
                        radius: r0 + t * (r1 - r0),
                    });
                }
            }
        }
    }

    /// The cost of the step from floor `from` of column `a` (unit direction `a_dir`) to floor
    /// `to` of the neighbouring column `b`, or `None` when the agent cannot take it: `to` more
    /// than the step limits above or below, a filled voxel in either column between its own
    /// floor and the higher floor plus the clearance (an overhang or a cave ceiling), or a rise
    /// or slope beyond the agent's limits. The conditions read the same from either end.
    #[inline]
    pub fn step(&self, a: ColumnView, a_dir: DVec3, from: Node, b: ColumnView, b_dir: DVec3, to: Node) -> Option<f64> {
        let h = i64::from(from.layer);
        let target = i64::from(to.layer);
        if target < h - self.scan_down || target > h + self.scan_up {
            return None;
        }
        // Voxel by voxel, each column must be open from just above its own floor up to the
        // higher floor plus the clearance: head room to climb, or the space dropped through.
        let top = h.max(target) + self.clearance;
        if !a.air(h + 1, top) || !b.air(target + 1, top) {
            return None;
        }
        let rise = to.radius - from.radius;
        if rise > self.agent.step_up || -rise > self.agent.step_down {
            return None;
        }
        let chord = (a_dir - b_dir).length();
        let horizontal = chord * 0.5 * (to.radius + from.radius);
        if rise * rise > self.slope2 * horizontal * horizontal {
            return None;
        }
        Some((horizontal * horizontal + rise * rise).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_view_is_filled_below_its_band_and_air_above_it() {
        let words = [0b1011u64];
        let v = ColumnView {
            base: 10,
            len: 4,
            words: &words,
        };
        let got: Vec<bool> = (7..16).map(|k| v.filled(k)).collect();
        assert_eq!(
            got,
            [true, true, true, true, true, false, true, false, false],
            "layers 7..16"
        );
        assert!(v.air(12, 12) && v.air(14, 40) && !v.air(12, 13) && !v.air(9, 9) && v.air(5, 4));
    }

    #[test]
    fn floors_need_air_above_and_their_clearance() {
        let rules = Rules::new(Agent::default(), 1.0);
        assert_eq!(rules.clearance, 2);
        // Layers 0..8: solid, solid, air, air, air, solid, air, solid (the last one is the top
        // sample: the layers above count as air).
        let d = [1.0, 0.5, -0.5, -1.0, -1.0, 2.0, -2.0, 1.0];
        let (mut words, mut nodes) = (Vec::new(), Vec::new());
        rules.column(3, &d, |k| k as f64, &mut words, &mut nodes);
        assert_eq!(words, vec![0b1010_0011]);
        // Layer 4 (b = 1): the crossing a third of the way up; layer 8 (b = 5) has one layer of
        // air under layer 10 (b = 7): no clearance; layer 10 is the last sample, no layer above.
        assert_eq!(nodes.len(), 1);
        assert_eq!(nodes[0].layer, 4);
        assert!((nodes[0].radius - (4.0 + 0.5)).abs() < 1e-12);
    }
}
