//! Queries: nodes, their positions and steps, and the nodes near a direction or a point.

use super::{NavGrid, Node, NodeId, Step};
use crate::agent::Agent;
use crate::columns::Columns;
use pmc_geometry::glam::DVec3;

impl NavGrid {
    /// The agent.
    pub fn agent(&self) -> &Agent {
        &self.agent
    }

    /// The columns.
    pub fn columns(&self) -> &Columns {
        &self.columns
    }

    /// Number of nodes.
    pub fn node_count(&self) -> usize {
        self.tile_base.last().copied().unwrap_or(0) as usize
    }

    /// Smallest radius of any node's surface point (for the A* heuristic).
    pub fn min_radius(&self) -> f64 {
        self.min_radius
    }

    /// The tile index and the local index of a canonical column in it.
    pub(super) fn locate(&self, column: u32) -> Option<(usize, usize)> {
        let place = self.columns.place_of(column);
        let t = self.tile_index(self.tile_of(place));
        let local = self.tiles.get(t)?.columns.binary_search(&column).ok()?;
        Some((t, local))
    }

    /// The nodes of `column` with their ids, lowest first.
    pub fn column_nodes(&self, column: u32) -> impl Iterator<Item = (NodeId, Node)> + '_ {
        let found = self.locate(column);
        let (t, range) = match found {
            Some((t, local)) => {
                let tile = &self.tiles[t];
                (t, tile.starts[local] as usize..tile.starts[local + 1] as usize)
            }
            None => (0, 0..0),
        };
        range.map(move |i| (NodeId(self.tile_base[t] + i as u32), self.tiles[t].nodes[i]))
    }

    /// The node `id`: its column and the node.
    pub fn node(&self, id: NodeId) -> Option<(u32, Node)> {
        if id.0 as usize >= self.node_count() {
            return None;
        }
        let t = self.tile_base.partition_point(|b| *b <= id.0) - 1;
        let tile = &self.tiles[t];
        let local = (id.0 - self.tile_base[t]) as usize;
        let col = tile.starts.partition_point(|s| *s as usize <= local) - 1;
        Some((tile.columns[col], tile.nodes[local]))
    }

    /// The surface point of node `id`, metres, planet-centred.
    pub fn position(&self, id: NodeId) -> Option<DVec3> {
        self.node(id).map(|(c, n)| self.columns.direction(c) * n.radius)
    }

    /// The steps from node (`column`, `node`) into the neighbouring column `to` (Fig. 11): one
    /// to each floor of `to` within the agent's step limits whose passage is open.
    pub fn steps_into(&self, column: u32, node: Node, to: u32) -> impl Iterator<Item = Step> + '_ {
        let (a, b) = (self.view(column), self.view(to));
        let from_dir = self.columns.direction(column);
        let to_dir = self.columns.direction(to);
        self.column_nodes(to).filter_map(move |(id, reached)| {
            self.rules
                .step(a, from_dir, node, b, to_dir, reached)
                .map(|cost| Step { to: id, cost })
        })
    }

    /// The steps the agent can take from node `id`.
    pub fn steps(&self, id: NodeId) -> Vec<Step> {
        let Some((column, node)) = self.node(id) else {
            return Vec::new();
        };
        self.columns
            .neighbours(column)
            .iter()
            .flat_map(|to| self.steps_into(column, node, *to))
            .collect()
    }

    /// The node nearest to direction `dir` (any non-zero vector): in the nearest column that has
    /// nodes (searching outward column by column, at most `max_rings` steps), the node whose
    /// surface radius is nearest to `radius`, or the highest node when `radius` is `None`.
    pub fn node_near(&self, dir: DVec3, radius: Option<f64>, max_rings: usize) -> Option<NodeId> {
        let start = self.columns.nearest(dir)?;
        let mut ring = vec![start];
        let mut seen = std::collections::HashSet::from([start]);
        for _ in 0..=max_rings {
            let mut best: Option<(f64, NodeId)> = None;
            for c in &ring {
                for (id, n) in self.column_nodes(*c) {
                    let score = match radius {
                        Some(r) => (n.radius - r).abs(),
                        None => -n.radius,
                    };
                    if best.is_none_or(|(s, _)| score < s) {
                        best = Some((score, id));
                    }
                }
            }
            if let Some((_, id)) = best {
                return Some(id);
            }
            let mut next = Vec::new();
            for c in &ring {
                for q in self.columns.neighbours(*c).iter() {
                    if seen.insert(*q) {
                        next.push(*q);
                    }
                }
            }
            ring = next;
        }
        None
    }

    /// The nodes whose surface points lie within `range` metres of `p` (planet frame), nearest
    /// column first, at most `limit`; and whether more were left out. Found by walking the
    /// columns outward from the one under `p`, so the cost follows the area asked for, not the
    /// planet's size.
    pub fn nodes_near(&self, p: DVec3, range: f64, limit: usize) -> (Vec<NodeId>, bool) {
        let mut out = Vec::new();
        let Some(start) = self.columns.nearest(p) else {
            return (out, false);
        };
        // A column can hold a node within range only if its direction is within this angle of
        // p's (nodes lie at radius at least min_radius); columns are walked while they are.
        let r = p.length();
        let reach = |c: u32| -> bool {
            let d = self.columns.direction(c);
            let angle = d.cross(p).length().atan2(d.dot(p));
            // Distance from p to the ray of the column, at its nearest: r sin(angle) when the
            // angle is below 90 degrees.
            angle <= std::f64::consts::FRAC_PI_2 && r * angle.sin() <= range * 1.5 + 1e-9
        };
        let mut seen = std::collections::HashSet::from([start]);
        let mut queue = std::collections::VecDeque::from([start]);
        let mut truncated = false;
        while let Some(c) = queue.pop_front() {
            let dir = self.columns.direction(c);
            for (id, n) in self.column_nodes(c) {
                if (dir * n.radius - p).length() <= range {
                    if out.len() == limit {
                        truncated = true;
                        return (out, truncated);
                    }
                    out.push(id);
                }
            }
            for q in self.columns.neighbours(c).iter() {
                if seen.insert(*q) && reach(*q) {
                    queue.push_back(*q);
                }
            }
        }
        (out, truncated)
    }
}
