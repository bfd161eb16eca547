//! The chunk octree of one selection and its balance (steps 2 and 5 of the rule in the crate
//! docs).
//!
//! # The tree
//!
//! An arena of nodes, each a leaf or split into its children (the eight slots of a split node
//! are consecutive; a slot past the shell's depth holds no chunk). The node holding a chunk is
//! found by walking down from its root. The chunks of a node's level around it on the same face
//! are found from its parent's: each lies in the parent's block of 3 x 3 x 3 chunks, so it is a
//! child of the parent or of a chunk beside the parent when that is split, else covered by it.
//! Split nodes remember what they found around them (the deepest node holding each of the 26
//! chunks of their level around them when last looked up, walked down from when split since),
//! so finding the 26 chunks around a leaf costs a few array reads. Steps that leave the face
//! (across a face edge, around a cube corner) go through [`adjacent`], whose chains of single
//! steps they are (remembered: they depend on the layout alone), and walk down from the root.
//!
//! # The test
//!
//! A leaf of level `L` must split when a cell it examines (a chunk of level `L - 1` outside it,
//! next to one of its children) is split, or when, around one of its edges, the two cells beside
//! a child are leaves finer than the leaf and than the cell across the edge. Away from the face's
//! border the cells are children of the 26 chunks of level `L` around the leaf, so the test reads
//! as: one of those chunks is split and has a split child touching the leaf; or, at a child of
//! the leaf and two of its axes, the chunks beside the child along each axis are split and the
//! one diagonally across (along both) exists and is not. (When no cell is split, a cell in a
//! split chunk is a leaf of level `L - 1`, and one in a chunk that is not split is covered by a
//! leaf of level `L` or coarser.)
//!
//! # Balance
//!
//! Leaves are split in rounds: every leaf that must split is tested against the tree as it
//! stands, then all of them are split. A round tests only *candidates*:
//!
//! - The first round tests every leaf beside (across a side, an edge or a corner, across face
//!   edges and next to cube corners too) a split chunk of the same level. That is every leaf that
//!   can need splitting: a leaf must split only when a cell it examines is split or covered by
//!   leaves finer than it, and then that cell's parent, a chunk of the leaf's level touching it,
//!   is split ([`adjacent`] finds exactly the chunks touching a chunk).
//! - Each later round tests the children of the chunks split in the round before and the leaves
//!   covering the 26 chunks around each of them: finer leaves around a split chunk see cells at
//!   least as coarse as themselves before and after it, so their tests cannot change.
//!
//! The set split in each round is therefore the set of all leaves that must split at that point,
//! whatever the order the candidates are tested in.

use crate::adjacency::adjacent;
#[cfg(test)]
use crate::adjacency::OFFSETS;
use pmc_geometry::{ChunkKey, ChunkSide, Layout, SideMask};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hasher for chunk keys: the five fields folded by multiplication, then mixed so that every
/// bit of the result depends on every field (hash maps index buckets by the low bits).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct KeyHasher(u64);

impl KeyHasher {
    #[inline]
    fn add(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
}

impl Hasher for KeyHasher {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.add(u64::from(*b));
        }
    }

    #[inline]
    fn write_u8(&mut self, n: u8) {
        self.add(u64::from(n));
    }

    #[inline]
    fn write_u32(&mut self, n: u32) {
        self.add(u64::from(n));
    }

    #[inline]
    fn write_u64(&mut self, n: u64) {
        self.add(n);
    }

    #[inline]
    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }

    #[inline]
    fn write_isize(&mut self, n: isize) {
        self.add(n as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        let z = self.0;
        let z = (z ^ (z >> 31)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z ^ (z >> 29)
    }
}

/// A hash map keyed by chunk keys.
pub(crate) type KeyMap<V> = HashMap<ChunkKey, V, BuildHasherDefault<KeyHasher>>;

/// The 27 offsets `[du, dv, dk]` of a 3 x 3 x 3 block, index `(du + 1) 9 + (dv + 1) 3 + dk + 1`.
const BLOCK: [[i8; 3]; 27] = block();
/// The index of the centre of [`BLOCK`].
const CENTRE: usize = 13;

const fn block() -> [[i8; 3]; 27] {
    let mut out = [[0i8; 3]; 27];
    let mut n = 0;
    while n < 27 {
        out[n] = [(n / 9) as i8 - 1, (n / 3 % 3) as i8 - 1, (n % 3) as i8 - 1];
        n += 1;
    }
    out
}

/// The index in [`BLOCK`] of an offset.
const fn block_index(o: [i8; 3]) -> usize {
    ((o[0] + 1) * 9 + (o[1] + 1) * 3 + o[2] + 1) as usize
}

/// A chunk's child slot in its parent, `4 i + 2 j + k` of the low bits: which half of the parent
/// it holds along `u`, `v` and depth.
fn half_bits(key: &ChunkKey) -> usize {
    ((key.i & 1) << 2 | (key.j & 1) << 1 | (key.k & 1)) as usize
}

/// For a chunk in child slot `h` and the chunk at `BLOCK[at]` from it: the latter's parent as a
/// [`BLOCK`] index from the former's parent, and its child slot there. `PARENT_AND_SLOT[h][at]`.
const PARENT_AND_SLOT: [[(usize, u32); 27]; 8] = parent_and_slot();

const fn parent_and_slot() -> [[(usize, u32); 27]; 8] {
    let mut out = [[(0usize, 0u32); 27]; 8];
    let mut h = 0;
    while h < 8 {
        let half = [(h >> 2 & 1) as i8, (h >> 1 & 1) as i8, (h & 1) as i8];
        let mut at = 0;
        while at < 27 {
            let mut up = [0i8; 3];
            let mut slot = 0u32;
            let mut a = 0;
            while a < 3 {
                // The position in doubled parent steps, -1 to 2: one parent down, this parent
                // (0 or 1), one parent up.
                let t = half[a] + BLOCK[at][a];
                up[a] = (t + 2) / 2 - 1;
                slot |= ((t + 2) as u32 & 1) << (2 - a);
                a += 1;
            }
            out[h][at] = (block_index(up), slot);
            at += 1;
        }
        h += 1;
    }
    out
}

/// For a chunk in child slot `h`, the [`BLOCK`] indices (from its parent) of the parent and of the
/// 7 chunks beside the parent towards the chunk: where the chunks around it lie.
const OCTANT: [[usize; 8]; 8] = octant();

const fn octant() -> [[usize; 8]; 8] {
    let mut out = [[0usize; 8]; 8];
    let mut h = 0;
    while h < 8 {
        let mut o = 0;
        while o < 8 {
            let mut up = [0i8; 3];
            let mut a = 0;
            while a < 3 {
                if o >> (2 - a) & 1 == 1 {
                    up[a] = (h >> (2 - a) & 1) as i8 * 2 - 1;
                }
                a += 1;
            }
            out[h][o] = block_index(up);
            o += 1;
        }
        h += 1;
    }
    out
}

/// For a chunk in child slot `h` and a [`BLOCK`] index `up` from its parent, the child slots of
/// the chunk there that are among the 26 chunks around it: `AROUND_SLOTS[h][up]`.
const AROUND_SLOTS: [[u8; 27]; 8] = around_slots();

const fn around_slots() -> [[u8; 27]; 8] {
    let mut out = [[0u8; 27]; 8];
    let mut h = 0;
    while h < 8 {
        let mut at = 0;
        while at < 27 {
            if at != CENTRE {
                let (up, slot) = PARENT_AND_SLOT[h][at];
                out[h][up] |= 1 << slot;
            }
            at += 1;
        }
        h += 1;
    }
    out
}

/// For the chunk at `BLOCK[at]` from a leaf, the mask of its child slots that touch the leaf:
/// along each axis where it lies beside the leaf, the half towards the leaf.
const TOUCH: [u8; 27] = touch();

const fn touch() -> [u8; 27] {
    let mut out = [0u8; 27];
    let mut at = 0;
    while at < 27 {
        let mut mask = 0u8;
        let mut slot = 0;
        while slot < 8 {
            let half = [(slot >> 2 & 1) as i8, (slot >> 1 & 1) as i8, (slot & 1) as i8];
            let mut touches = true;
            let mut a = 0;
            while a < 3 {
                // Beside the leaf on the + side, its half 0 touches the leaf; on the - side, 1.
                let o = BLOCK[at][a];
                if (o == 1 && half[a] != 0) || (o == -1 && half[a] != 1) {
                    touches = false;
                }
                a += 1;
            }
            if touches {
                mask |= 1 << slot;
            }
            slot += 1;
        }
        out[at] = mask;
        at += 1;
    }
    out
}

/// For child slot `n` of a leaf, its three edges' halves: the [`BLOCK`] indices (from the leaf)
/// of the chunks beside the child along one axis, along the other, and across both, going out of
/// the leaf. The axis pairs are `(u, v)`, `(u, depth)`, `(v, depth)`.
const EDGES: [[(usize, usize, usize); 3]; 8] = edges();

const fn edges() -> [[(usize, usize, usize); 3]; 8] {
    let mut out = [[(0usize, 0usize, 0usize); 3]; 8];
    let mut n = 0;
    while n < 8 {
        let out_dir = [
            (n >> 2 & 1) as i8 * 2 - 1,
            (n >> 1 & 1) as i8 * 2 - 1,
            (n & 1) as i8 * 2 - 1,
        ];
        let pairs = [(0, 1), (0, 2), (1, 2)];
        let mut e = 0;
        while e < 3 {
            let (a, b) = pairs[e];
            let mut oa = [0i8; 3];
            oa[a] = out_dir[a];
            let mut ob = [0i8; 3];
            ob[b] = out_dir[b];
            let mut oab = [0i8; 3];
            oab[a] = out_dir[a];
            oab[b] = out_dir[b];
            out[n][e] = (block_index(oa), block_index(ob), block_index(oab));
            e += 1;
        }
        n += 1;
    }
    out
}

/// The offset towards a chunk side (its axis, signed).
fn side_offset(side: ChunkSide) -> [i8; 3] {
    let mut o = [0i8; 3];
    o[side.axis()] = if side.is_max() { 1 } else { -1 };
    o
}

/// No node: a leaf's children, a chunk that does not exist.
const NONE: u32 = u32::MAX;
/// A remembered neighbour not looked up yet.
const UNKNOWN: u32 = u32::MAX - 1;

/// A chunk of the tree.
#[derive(Clone, Copy, Debug)]
struct Node {
    key: ChunkKey,
    /// The parent node, [`NONE`] for a root.
    parent: u32,
    /// The first of the eight child slots, [`NONE`] for a leaf.
    children: u32,
    /// Where its 27 entries of [`Tree::around`] start, [`NONE`] before they are needed.
    around: u32,
    /// The last balance round that listed this node as a candidate.
    listed: u32,
    /// The child slots that are split (bit = slot).
    split_children: u8,
    /// Whether the slot holds a chunk of the layout (children past the shell's depth do not).
    exists: bool,
    /// Whether the chunks of its level around it all lie on its face.
    interior: bool,
}

/// A cell a leaf on a face's border examines (a chunk of the next finer level next to one of its
/// children).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cell {
    /// There is no such chunk.
    None,
    /// Covered by a leaf of this level.
    Level(i32),
    /// Split into finer leaves.
    Split,
}

/// The leaves and split chunks of the octree of one selection.
#[derive(Clone, Debug)]
pub(crate) struct Tree<'a> {
    layout: &'a Layout,
    max_level: u8,
    /// Chunks per face side and along depth, by level.
    per_side: Vec<i64>,
    depth: Vec<i64>,
    /// The nodes; the first are the roots, every chunk of the coarsest level in key order.
    nodes: Vec<Node>,
    /// For the nodes that needed them, 27 entries (by [`BLOCK`] index): the deepest node holding
    /// the chunk of the node's level at that offset on the same face when last looked up,
    /// [`NONE`] when there is no such chunk, [`UNKNOWN`] before the first lookup.
    around: Vec<u32>,
    leaves: usize,
    round: u32,
    /// The steps that left a face, by chunk and [`BLOCK`] index: the chunk reached, if any.
    off_face: HashMap<(ChunkKey, u8), Option<ChunkKey>, BuildHasherDefault<KeyHasher>>,
}

impl<'a> Tree<'a> {
    /// An empty tree for `layout` (see [`Tree::build`]).
    pub(crate) fn new(layout: &'a Layout) -> Tree<'a> {
        let levels = 0..=layout.max_level();
        Tree {
            layout,
            max_level: layout.max_level(),
            per_side: levels.clone().map(|l| i64::from(layout.chunks_per_side(l))).collect(),
            depth: levels.map(|l| i64::from(layout.depth_chunks(l))).collect(),
            nodes: Vec::new(),
            around: Vec::new(),
            leaves: 0,
            round: 0,
            off_face: HashMap::default(),
        }
    }

    /// Makes this the tree of `roots` (every chunk of the layout's coarsest level, in key order)
    /// with `splits` applied in order (each a leaf when it comes), then balanced; balancing stops
    /// early once the tree holds more than `limit` leaves (the tree is then only good for its
    /// [`Tree::leaf_count`]: more than `limit`).
    pub(crate) fn build(&mut self, roots: &[ChunkKey], splits: &[ChunkKey], cap: u8, limit: usize) {
        self.nodes.clear();
        self.around.clear();
        self.round = 0;
        for key in roots {
            debug_assert_eq!(key.level, self.max_level);
            self.push(*key, NONE, true);
        }
        self.leaves = roots.len();
        for key in splits {
            let node = self.find(key);
            debug_assert!(self.nodes[node as usize].key == *key);
            self.split(node);
        }
        // The roots alone are all of one level: balanced already.
        if !splits.is_empty() {
            self.balance(cap, limit);
        }
    }

    fn push(&mut self, key: ChunkKey, parent: u32, exists: bool) {
        let interior = self.interior(&key);
        self.nodes.push(Node {
            key,
            parent,
            children: NONE,
            around: NONE,
            listed: 0,
            split_children: 0,
            exists,
            interior,
        });
    }

    /// How many leaves the tree holds.
    pub(crate) fn leaf_count(&self) -> usize {
        self.leaves
    }

    /// The leaves, in key order, with their nodes.
    pub(crate) fn leaves(&self) -> Vec<(ChunkKey, u32)> {
        let mut out: Vec<(ChunkKey, u32)> = (0..self.nodes.len() as u32)
            .filter(|n| self.nodes[*n as usize].exists && self.is_leaf_node(*n))
            .map(|n| (self.nodes[n as usize].key, n))
            .collect();
        out.sort_unstable();
        out
    }

    fn is_leaf_node(&self, node: u32) -> bool {
        self.nodes[node as usize].children == NONE
    }

    /// Whether `key` is a leaf.
    #[cfg(test)]
    pub(crate) fn is_leaf(&self, key: &ChunkKey) -> bool {
        let node = self.find(key);
        self.nodes[node as usize].key == *key && self.is_leaf_node(node)
    }

    /// Splits the leaf `node`: its children that are chunks of the layout become leaves.
    fn split(&mut self, node: u32) {
        let n = self.nodes[node as usize];
        debug_assert!(n.children == NONE && n.exists, "{} is not a leaf", n.key);
        let Some(children) = n.key.children() else {
            return;
        };
        self.nodes[node as usize].children = self.nodes.len() as u32;
        if n.parent != NONE {
            self.nodes[n.parent as usize].split_children |= 1 << half_bits(&n.key);
        }
        self.leaves -= 1;
        for child in children {
            let exists = self.layout.contains_chunk(&child);
            self.push(child, node, exists);
            self.leaves += usize::from(exists);
        }
    }

    /// Splits the leaf `key`, appending its children that are chunks of the layout to `out`.
    #[cfg(test)]
    pub(crate) fn split_key(&mut self, key: &ChunkKey, out: &mut Vec<ChunkKey>) {
        let node = self.find(key);
        assert!(self.nodes[node as usize].key == *key);
        self.split(node);
        let first = self.nodes[node as usize].children as usize;
        out.extend(self.nodes[first..first + 8].iter().filter(|n| n.exists).map(|n| n.key));
    }

    /// From `node`, which holds `target` (on the same face, at its level or coarser), down to
    /// the deepest node holding `target`: the leaf covering it, or `target`'s own node.
    fn descend(&self, mut node: u32, target: &ChunkKey) -> u32 {
        loop {
            let n = &self.nodes[node as usize];
            if n.children == NONE || n.key.level <= target.level {
                return node;
            }
            let s = n.key.level - 1 - target.level;
            let slot = (target.i >> s & 1) << 2 | (target.j >> s & 1) << 1 | (target.k >> s & 1);
            node = n.children + slot;
        }
    }

    /// The deepest node holding `key` (a chunk of the layout).
    fn find(&self, key: &ChunkKey) -> u32 {
        let up = self.max_level - key.level;
        let top = usize::from(self.max_level);
        let (n, d) = (self.per_side[top], self.depth[top]);
        let root = ((key.face.index() as i64 * n + i64::from(key.i >> up)) * n + i64::from(key.j >> up)) * d
            + i64::from(key.k >> up);
        self.descend(root as u32, key)
    }

    /// The leaf holding `cell` (`cell` itself or an ancestor), `None` when `cell` is split into
    /// finer leaves.
    fn covering(&self, cell: &ChunkKey) -> Option<ChunkKey> {
        let node = self.find(cell);
        self.is_leaf_node(node).then(|| self.nodes[node as usize].key)
    }

    /// Whether the chunks of `key`'s level around `key` all lie on its face.
    fn interior(&self, key: &ChunkKey) -> bool {
        let n = self.per_side[usize::from(key.level)];
        let (i, j) = (i64::from(key.i), i64::from(key.j));
        i >= 1 && i + 1 < n && j >= 1 && j + 1 < n
    }

    /// The chunk of `key`'s level at `offset` from `key` on the same face, `None` past the face's
    /// border or the shell's depth.
    fn on_face(&self, key: &ChunkKey, offset: [i8; 3]) -> Option<ChunkKey> {
        let level = usize::from(key.level);
        let n = self.per_side[level];
        let i = i64::from(key.i) + i64::from(offset[0]);
        let j = i64::from(key.j) + i64::from(offset[1]);
        let k = i64::from(key.k) + i64::from(offset[2]);
        ((0..n).contains(&i) && (0..n).contains(&j) && (0..self.depth[level]).contains(&k)).then_some(ChunkKey {
            face: key.face,
            level: key.level,
            i: i as u32,
            j: j as u32,
            k: k as u32,
        })
    }

    /// The chunk of `key`'s level at `offset` from `key`: [`adjacent`], by index arithmetic when
    /// the step stays on the face.
    /// Steps that leave the face are remembered (they depend on the layout alone).
    fn step(&mut self, key: &ChunkKey, offset: [i8; 3]) -> Option<ChunkKey> {
        let n = self.per_side[usize::from(key.level)];
        let i = i64::from(key.i) + i64::from(offset[0]);
        let j = i64::from(key.j) + i64::from(offset[1]);
        if (0..n).contains(&i) && (0..n).contains(&j) {
            return self.on_face(key, offset);
        }
        let layout = self.layout;
        *self
            .off_face
            .entry((*key, block_index(offset) as u8))
            .or_insert_with(|| adjacent(layout, key, offset))
    }

    /// Whether the chunk at `BLOCK[at]` from `key` lies past the shell's depth.
    fn past_depth(&self, key: &ChunkKey, at: usize) -> bool {
        let k = i64::from(key.k) + i64::from(BLOCK[at][2]);
        k < 0 || k >= self.depth[usize::from(key.level)]
    }

    /// The deepest node holding the chunk at `BLOCK[at]` from `node` on the same face, [`NONE`]
    /// when there is no such chunk or it lies past the face's border; remembered.
    #[inline]
    fn around(&mut self, node: u32, at: usize) -> u32 {
        // What was found before, when it is a leaf or the chunk's own node.
        let n = &self.nodes[node as usize];
        if n.around != NONE {
            let known = self.around[n.around as usize + at];
            if known == NONE {
                return NONE;
            }
            if known != UNKNOWN {
                let k = &self.nodes[known as usize];
                if k.children == NONE || k.key.level == n.key.level {
                    return known;
                }
            }
        }
        self.look_around(node, at)
    }

    /// [`Tree::around`] when what was found before (if anything) has been split since.
    #[inline(never)]
    fn look_around(&mut self, node: u32, at: usize) -> u32 {
        let n = &self.nodes[node as usize];
        let (key, parent, interior, mut base) = (n.key, n.parent, n.interior, n.around);
        if base == NONE {
            base = self.around.len() as u32;
            self.around.extend([UNKNOWN; 27]);
            self.nodes[node as usize].around = base;
        }
        let slot = base as usize + at;
        let known = self.around[slot];
        let found = if known == NONE {
            return NONE;
        } else if known != UNKNOWN {
            let k = &self.nodes[known as usize];
            if k.children == NONE || k.key.level == key.level {
                return known;
            }
            // A coarser leaf when last looked up, split since.
            match self.on_face(&key, BLOCK[at]) {
                Some(target) => self.descend(known, &target),
                None => NONE,
            }
        } else if parent == NONE || !interior {
            match self.on_face(&key, BLOCK[at]) {
                None => NONE,
                Some(target) if parent == NONE => self.find(&target),
                Some(_) => self.via_parent(&key, parent, at),
            }
        } else {
            self.via_parent(&key, parent, at)
        };
        self.around[slot] = found;
        found
    }

    /// The deepest node holding the chunk at `BLOCK[at]` from `key` (a node of the tree with
    /// that `parent`; the chunk not past the face's border), from what lies around the parent:
    /// the chunk's parent is the parent or beside it; when split, the chunk is one of its
    /// children, else that node covers it.
    fn via_parent(&mut self, key: &ChunkKey, parent: u32, at: usize) -> u32 {
        // Past the shell's depth (a coarser leaf may cover the place where it would be).
        if self.past_depth(key, at) {
            return NONE;
        }
        let (up, slot) = PARENT_AND_SLOT[half_bits(key)][at];
        let holder = if up == CENTRE { parent } else { self.around(parent, up) };
        if holder == NONE {
            return NONE;
        }
        let children = self.nodes[holder as usize].children;
        if children == NONE {
            holder
        } else {
            children + slot
        }
    }

    /// The deepest nodes holding the 26 chunks around `node` (a node away from the face's border,
    /// not a root), by [`BLOCK`] index; [`NONE`] where there is no such chunk and at the centre.
    fn neighbours(&mut self, node: u32) -> [u32; 27] {
        let n = &self.nodes[node as usize];
        let (key, parent) = (n.key, n.parent);
        let h = half_bits(&key);
        // The chunk's parent is the node's parent or one of the 7 chunks beside it towards the
        // node (the octant of the node's child slot).
        let mut holders = [NONE; 27];
        for &at in &OCTANT[h] {
            holders[at] = if at == CENTRE { parent } else { self.around(parent, at) };
        }
        // Along depth, the chunks below or above may not exist even where the parent level has
        // a chunk (a coarser leaf may cover the place where they would be).
        let below = key.k > 0;
        let above = i64::from(key.k) + 1 < self.depth[usize::from(key.level)];
        let mut out = [NONE; 27];
        for (at, found) in out.iter_mut().enumerate() {
            let dk = BLOCK[at][2];
            if at == CENTRE || (dk < 0 && !below) || (dk > 0 && !above) {
                continue;
            }
            let (up, slot) = PARENT_AND_SLOT[h][at];
            let holder = holders[up];
            if holder != NONE {
                let children = self.nodes[holder as usize].children;
                *found = if children == NONE { holder } else { children + slot };
            }
        }
        out
    }

    /// Whether the leaf `node` must split: a touching leaf is more than one level finer, or one of
    /// its edges has the checkerboard (this leaf and the leaf diagonally across the edge coarser
    /// than both leaves beside it). See the module docs.
    fn must_split(&mut self, node: u32, cap: u8) -> bool {
        let n = self.nodes[node as usize];
        let key = n.key;
        if key.level <= cap || key.level == 0 {
            return false;
        }
        if !n.interior || n.parent == NONE {
            return self.must_split_anywhere(&key);
        }
        // What holds the chunks' parents: the leaf's parent and the 7 chunks beside it towards
        // the leaf. For each, whether it exists, its first child slot and its split children
        // when it is split (a chunk of the parent's level; else it covers its part).
        let h = half_bits(&key);
        let mut holders = [(false, NONE, 0u8); 27];
        for &at in &OCTANT[h] {
            let holder = if at == CENTRE {
                n.parent
            } else {
                self.around(n.parent, at)
            };
            if holder != NONE {
                let q = &self.nodes[holder as usize];
                holders[at] = (true, q.children, if q.children == NONE { 0 } else { q.split_children });
            }
        }
        // Without a split chunk of this level around, the leaf need not split.
        if OCTANT[h].iter().all(|&at| holders[at].2 & AROUND_SLOTS[h][at] == 0) {
            return false;
        }
        let below = key.k > 0;
        let above = i64::from(key.k) + 1 < self.depth[usize::from(key.level)];
        // The chunks around the leaf that exist, and those that are split.
        let mut exists = [false; 27];
        let mut split = [false; 27];
        let mut any = false;
        for at in 0..27 {
            let dk = BLOCK[at][2];
            if at == CENTRE || (dk < 0 && !below) || (dk > 0 && !above) {
                continue;
            }
            let (up, slot) = PARENT_AND_SLOT[h][at];
            let (there, children, split_children) = holders[up];
            exists[at] = there;
            if split_children >> slot & 1 == 1 {
                // A split chunk of this level: a split child touching the leaf is a split cell.
                if self.nodes[(children + slot) as usize].split_children & TOUCH[at] != 0 {
                    return true;
                }
                split[at] = true;
                any = true;
            }
        }
        if !any {
            return false;
        }
        // The upper children exist when the level below has a chunk there.
        let upper = 2 * i64::from(key.k) + 1 < self.depth[usize::from(key.level) - 1];
        for (child, edges) in EDGES.iter().enumerate() {
            if child & 1 == 1 && !upper {
                continue;
            }
            for &(a, b, across) in edges {
                if split[a] && split[b] && exists[across] && !split[across] {
                    return true;
                }
            }
        }
        false
    }

    /// [`Tree::must_split`] for any leaf (on a face's border too), cell by cell.
    fn must_split_anywhere(&mut self, key: &ChunkKey) -> bool {
        let level = i32::from(key.level);
        let Some(children) = key.children() else {
            return false;
        };
        for (n, child) in children.iter().enumerate() {
            if !self.layout.contains_chunk(child) {
                continue;
            }
            // The way out of this chunk from the child along u, v and depth.
            let out = [
                (n >> 2 & 1) as i8 * 2 - 1,
                (n >> 1 & 1) as i8 * 2 - 1,
                (n & 1) as i8 * 2 - 1,
            ];
            // The cells beside, along an edge from and across a corner from the child (outside
            // this chunk), by the mask of the axes stepped along.
            let mut cells = [Cell::None; 8];
            for (mask, cell) in cells.iter_mut().enumerate().skip(1) {
                let offset = [0, 1, 2].map(|a| if mask >> a & 1 == 1 { out[a] } else { 0 });
                *cell = match self.step(child, offset) {
                    None => Cell::None,
                    Some(c) => match self.covering(&c) {
                        Some(leaf) => Cell::Level(i32::from(leaf.level)),
                        None => Cell::Split,
                    },
                };
                // The level-(L-1) cells around the child outside this chunk must not be split.
                if *cell == Cell::Split {
                    return true;
                }
            }
            // The half of each edge of this chunk that the child holds.
            for (p, q) in [(1usize, 2usize), (1, 4), (2, 4)] {
                if let (Cell::Level(bp), Cell::Level(bq), Cell::Level(ac)) = (cells[p], cells[q], cells[p | q]) {
                    if level.min(ac) > bp.max(bq) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// [`Tree::must_split`] of the leaf `key`.
    #[cfg(test)]
    pub(crate) fn must_split_key(&mut self, key: &ChunkKey, cap: u8) -> bool {
        let node = self.find(key);
        assert!(self.nodes[node as usize].key == *key && self.is_leaf_node(node));
        self.must_split(node, cap)
    }

    /// Lists `node` as a candidate of the current round, once.
    fn list(&mut self, node: u32, out: &mut Vec<u32>) {
        let n = &mut self.nodes[node as usize];
        if n.listed != self.round {
            n.listed = self.round;
            out.push(node);
        }
    }

    /// The leaves the first round of [`Tree::balance`] must test (see the module docs): the
    /// leaves around split chunks of their level.
    fn first_candidates(&mut self) -> Vec<u32> {
        let mut out = Vec::new();
        for node in 0..self.nodes.len() as u32 {
            let n = self.nodes[node as usize];
            if !n.exists || n.children == NONE {
                continue;
            }
            for b in self.beside(node) {
                if b != NONE && self.is_leaf_node(b) && self.nodes[b as usize].key.level == n.key.level {
                    self.list(b, &mut out);
                }
            }
        }
        out
    }

    /// The deepest nodes holding the 26 chunks around `node`, across face edges too, by
    /// [`BLOCK`] index; [`NONE`] where there is no such chunk and at the centre.
    fn beside(&mut self, node: u32) -> [u32; 27] {
        let n = self.nodes[node as usize];
        if n.interior && n.parent != NONE {
            return self.neighbours(node);
        }
        let mut out = [NONE; 27];
        for (at, found) in out.iter_mut().enumerate() {
            if at != CENTRE {
                if let Some(c) = self.step(&n.key, BLOCK[at]) {
                    *found = self.find(&c);
                }
            }
        }
        out
    }

    /// Splits leaves until none must split, in rounds (see the module docs); stops once there
    /// are more than `limit` leaves.
    pub(crate) fn balance(&mut self, cap: u8, limit: usize) {
        self.round = 1;
        let mut candidates = self.first_candidates();
        let mut splits = Vec::new();
        loop {
            if self.leaves > limit {
                return;
            }
            splits.clear();
            for &node in &candidates {
                if self.is_leaf_node(node) && self.must_split(node, cap) {
                    splits.push(node);
                }
            }
            if splits.is_empty() {
                return;
            }
            self.round += 1;
            candidates.clear();
            for &node in &splits {
                self.split(node);
                let first = self.nodes[node as usize].children;
                for child in first..first + 8 {
                    if self.nodes[child as usize].exists {
                        self.list(child, &mut candidates);
                    }
                }
            }
            for &node in &splits {
                for b in self.beside(node) {
                    if b != NONE && self.is_leaf_node(b) {
                        self.list(b, &mut candidates);
                    }
                }
            }
        }
    }

    /// The sides of the leaf `node` across which the leaf is one level coarser.
    pub(crate) fn coarser(&mut self, node: u32) -> SideMask {
        let n = self.nodes[node as usize];
        let fast = n.interior && n.parent != NONE;
        let mut mask = SideMask::NONE;
        for side in ChunkSide::ALL {
            let offset = side_offset(side);
            let found = if fast {
                self.via_parent(&n.key, n.parent, block_index(offset))
            } else {
                match self.step(&n.key, offset) {
                    Some(cell) => self.find(&cell),
                    None => NONE,
                }
            };
            if found != NONE && self.is_leaf_node(found) && self.nodes[found as usize].key.level == n.key.level + 1 {
                mask = mask.with(side);
            }
        }
        mask
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pmc_geometry::Face;
    use std::hash::BuildHasher;

    #[test]
    fn the_block_offsets_are_indexed_as_documented() {
        for (n, o) in BLOCK.iter().enumerate() {
            assert_eq!(block_index(*o), n);
        }
        assert_eq!(BLOCK[CENTRE], [0, 0, 0]);
        let others: Vec<[i8; 3]> = BLOCK.iter().copied().filter(|o| *o != [0, 0, 0]).collect();
        assert_eq!(others, OFFSETS.to_vec());
    }

    /// The tables agree with the chunk keys they stand for, on a face large enough for every
    /// step to stay on it.
    #[test]
    fn the_tables_follow_the_keys() {
        let key = ChunkKey {
            face: Face::East,
            level: 2,
            i: 5,
            j: 6,
            k: 9,
        };
        for child in key.children().unwrap() {
            let h = half_bits(&child);
            for (at, o) in BLOCK.iter().enumerate() {
                let at_key = ChunkKey {
                    i: (i64::from(child.i) + i64::from(o[0])) as u32,
                    j: (i64::from(child.j) + i64::from(o[1])) as u32,
                    k: (i64::from(child.k) + i64::from(o[2])) as u32,
                    ..child
                };
                let (up, slot) = PARENT_AND_SLOT[h][at];
                let p = at_key.parent();
                assert_eq!(
                    [
                        p.i as i64 - key.i as i64,
                        p.j as i64 - key.j as i64,
                        p.k as i64 - key.k as i64
                    ],
                    BLOCK[up].map(i64::from)
                );
                assert_eq!(p.children().unwrap()[slot as usize], at_key);
                // The children of that chunk touching the leaf `child`: those in the block of
                // 4 x 4 x 4 chunks of their level around it.
                if at == CENTRE {
                    continue;
                }
                for (s, c) in at_key.children().unwrap().iter().enumerate() {
                    let touching = [(c.i, child.i), (c.j, child.j), (c.k, child.k)]
                        .iter()
                        .all(|(a, b)| (2 * i64::from(*b) - 1..=2 * i64::from(*b) + 2).contains(&i64::from(*a)));
                    assert_eq!(TOUCH[at] >> s & 1 == 1, touching, "{at} {s}");
                }
            }
        }
        for (n, edges) in EDGES.iter().enumerate() {
            let out = [
                (n >> 2 & 1) as i8 * 2 - 1,
                (n >> 1 & 1) as i8 * 2 - 1,
                (n & 1) as i8 * 2 - 1,
            ];
            for (e, (a, b)) in [(0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
                let (ia, ib, iab) = edges[e];
                assert_eq!(BLOCK[ia][a], out[a]);
                assert_eq!(BLOCK[ib][b], out[b]);
                assert_eq!(
                    BLOCK[iab],
                    std::array::from_fn(|x| if x == a || x == b { out[x] } else { 0 })
                );
            }
        }
    }

    /// Steps on the face by index arithmetic equal the chains of single steps, and steps across
    /// face edges and cube corners are those chains.
    #[test]
    fn steps_equal_adjacent_everywhere() {
        for layout in [
            Layout::new(4, 4, 100.0, 1.0, 4).unwrap(),
            Layout::new(8, 2, 50.0, 2.0, 3).unwrap(),
            Layout::new(3, 3, 50.0, 2.0, 2).unwrap(),
        ] {
            let mut tree = Tree::new(&layout);
            for level in 0..=layout.max_level() {
                for key in layout.chunks(level) {
                    for o in OFFSETS {
                        assert_eq!(tree.step(&key, o), adjacent(&layout, &key, o), "{key} {o:?}");
                    }
                    for side in ChunkSide::ALL {
                        assert_eq!(
                            tree.step(&key, side_offset(side)),
                            layout.neighbour(&key, side, level),
                            "{key} {side:?}"
                        );
                    }
                }
            }
        }
    }

    /// What the nodes remember around them, and the chunks around a leaf found from its parent,
    /// are what walks down from the roots find, after every split of a random tree.
    #[test]
    fn neighbours_follow_the_splits() {
        let layout = Layout::new(16, 2, 50.0, 2.0, 5).unwrap();
        let mut tree = Tree::new(&layout);
        let roots = layout.chunks(layout.max_level());
        tree.build(&roots, &[], 0, usize::MAX);
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut checked = 0;
        for _ in 0..300 {
            let leaves: Vec<u32> = (0..tree.nodes.len() as u32)
                .filter(|n| {
                    let node = &tree.nodes[*n as usize];
                    node.exists && node.children == NONE && node.key.level > 0
                })
                .collect();
            if leaves.is_empty() {
                break;
            }
            tree.split(leaves[next() as usize % leaves.len()]);
            for _ in 0..20 {
                let n = next() as u32 % tree.nodes.len() as u32;
                let node = tree.nodes[n as usize];
                if !node.exists {
                    continue;
                }
                let at = next() as usize % 27;
                let expected = match tree.on_face(&node.key, BLOCK[at]) {
                    None => NONE,
                    Some(target) => tree.find(&target),
                };
                assert_eq!(tree.around(n, at), expected, "{} {:?}", node.key, BLOCK[at]);
                if node.interior && node.parent != NONE {
                    let all = tree.neighbours(n);
                    for (at, found) in all.iter().enumerate() {
                        let expected = match tree.on_face(&node.key, BLOCK[at]) {
                            Some(target) if at != CENTRE => tree.find(&target),
                            _ => NONE,
                        };
                        assert_eq!(*found, expected, "{} {:?}", node.key, BLOCK[at]);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    /// Keys that differ in one field land in different low bits: the hasher spreads them.
    #[test]
    fn the_hasher_spreads_nearby_keys() {
        let build = BuildHasherDefault::<KeyHasher>::default();
        let mut buckets = std::collections::HashSet::new();
        let mut count = 0;
        for i in 0..16u32 {
            for j in 0..16u32 {
                for k in 0..4u32 {
                    let key = ChunkKey::new(Face::Top, 1000 + i, 2000 + j, k);
                    buckets.insert(build.hash_one(key) & 1023);
                    count += 1;
                }
            }
        }
        // 1024 keys in 1024 buckets: a uniform hash fills about 63% of them.
        assert!(buckets.len() > 550, "{} of {count}", buckets.len());
    }
}
