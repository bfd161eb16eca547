//! The 26 chunks around a chunk at its own level: across its six sides, its twelve edges and its
//! eight corners, across face edges and next to cube corners too.
//!
//! A step across one side is [`Layout::neighbour`]. A step across two or three sides is a chain
//! of single steps; the side names are those of the face the chain starts on, so a step that
//! leaves the face (across a face edge) must come last among the steps along the face: the chain
//! takes the step that stays on the face first. Depth steps keep the face, `i` and `j`, so they
//! come last of all. When both face steps leave the face the corner lies past a cube corner,
//! where only three faces meet: there is no such chunk (the three chunks around that corner
//! column are the chunk and its two side neighbours).

use pmc_geometry::{ChunkKey, ChunkSide, Layout};

/// The 26 offsets `[du, dv, dk]` (each `-1`, `0` or `1`, not all zero) along the face's `u`, `v`
/// and depth axes, in lexicographic order.
pub const OFFSETS: [[i8; 3]; 26] = offsets();

const fn offsets() -> [[i8; 3]; 26] {
    let mut out = [[0i8; 3]; 26];
    let mut n = 0;
    let mut a = -1i8;
    while a <= 1 {
        let mut b = -1i8;
        while b <= 1 {
            let mut c = -1i8;
            while c <= 1 {
                if a != 0 || b != 0 || c != 0 {
                    out[n] = [a, b, c];
                    n += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    out
}

/// The side of `axis` (0: `u`, 1: `v`, 2: depth) a step of `d` crosses, `None` for no step.
fn side(axis: usize, d: i8) -> Option<ChunkSide> {
    let (lo, hi) = match axis {
        0 => (ChunkSide::UMin, ChunkSide::UMax),
        1 => (ChunkSide::VMin, ChunkSide::VMax),
        _ => (ChunkSide::Inner, ChunkSide::Outer),
    };
    match d {
        0 => None,
        d if d < 0 => Some(lo),
        _ => Some(hi),
    }
}

/// The chunk of `key`'s level at `offset` (`[du, dv, dk]`, see [`OFFSETS`]) from `key`: across
/// one side, one edge or one corner.
///
/// `None` past the shell's inner or outer boundary, past a cube corner (both face steps leave
/// the face), when `key` is not a chunk of `layout`, or when a component of `offset` is not `-1`,
/// `0` or `1` or all are `0`.
pub fn adjacent(layout: &Layout, key: &ChunkKey, offset: [i8; 3]) -> Option<ChunkKey> {
    if offset.iter().any(|d| !(-1..=1).contains(d)) || offset == [0, 0, 0] || !layout.contains_chunk(key) {
        return None;
    }
    let level = key.level;
    let step = |k: &ChunkKey, s: ChunkSide| layout.neighbour(k, s, level);
    let mut cur = *key;
    match (side(0, offset[0]), side(1, offset[1])) {
        (None, None) => {}
        (Some(s), None) | (None, Some(s)) => cur = step(&cur, s)?,
        (Some(su), Some(sv)) => {
            let first = step(&cur, su)?;
            if first.face == cur.face {
                cur = step(&first, sv)?;
            } else {
                let other = step(&cur, sv)?;
                if other.face != cur.face {
                    return None;
                }
                cur = step(&other, su)?;
            }
        }
    }
    if let Some(s) = side(2, offset[2]) {
        cur = step(&cur, s)?;
    }
    Some(cur)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Face;

    #[test]
    fn offsets_are_the_26_neighbours() {
        let set: std::collections::BTreeSet<[i8; 3]> = OFFSETS.into_iter().collect();
        assert_eq!(set.len(), 26);
        assert!(!set.contains(&[0, 0, 0]));
        assert!(OFFSETS.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn bad_offsets_and_keys_give_none() {
        let l = Layout::new(2, 4, 50.0, 1.0, 2).unwrap();
        let key = ChunkKey::new(Face::Top, 0, 0, 0);
        assert_eq!(adjacent(&l, &key, [0, 0, 0]), None);
        assert_eq!(adjacent(&l, &key, [2, 0, 0]), None);
        assert_eq!(adjacent(&l, &ChunkKey::new(Face::Top, 5, 0, 0), [1, 0, 0]), None);
        assert_eq!(adjacent(&l, &key, [0, 0, -1]), None);
        assert_eq!(adjacent(&l, &key, [0, 0, 1]), Some(ChunkKey::new(Face::Top, 0, 0, 1)));
        assert_eq!(adjacent(&l, &key, [1, 1, 1]), Some(ChunkKey::new(Face::Top, 1, 1, 1)));
        // (0, 0) of a two-chunk face: both face steps towards -u and -v leave the face.
        assert_eq!(adjacent(&l, &key, [-1, -1, 0]), None);
    }
}
