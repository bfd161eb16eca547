//! The material model of the column presets (earthlike, moon, mars): one set of rules in one
//! order, which each planet fills in with its own parameters.
//!
//! # Why one model
//!
//! The planets place their materials the same way: cave rock well under the surface, ice or
//! snow on flat ground towards the poles or high up, rock on steep slopes and rough ground, a
//! material where a field of the terrain is strong (dunes, maria), and the rest one ground
//! material or bands by height (shore, lowlands, forest, bare rock). One model keeps the rules,
//! their order, the column lookups and the batched noise in one place, so the planets agree on
//! what a rule means and a new planet is a table of parameters.
//!
//! # What is per planet
//!
//! - its column model (the shape of the terrain), and what the rules read of a column
//!   ([`GroundModel`], [`Ground`]: surface radius, overhang amplitude, feature field, roughness);
//! - which rules apply and their thresholds ([`MaterialRules`]), in the layout's units;
//! - its materials, colours and blend colours ([`Look`]).
//!
//! The earth preset and the height-field terrains read fields the columns here do not have
//! (climate lines in true-scale metres, deserts, the shelf), so they implement [`MaterialMap`]
//! themselves and share the shader ([`super::shading::PaletteShader`]) and [`Look`].
//!
//! # The rules
//!
//! The first that holds gives the material; `up` is the normal's component along the direction
//! from the planet's centre, `j` the jitter noise, `z` the height above the datum, jittered:
//!
//! 1. [`CaveRock`]: deeper under the column's surface than `max(depth, amp + margin)`;
//! 2. [`Cap`]: ice or snow where `up > flat`, poleward of a latitude or above a snow line;
//! 3. [`SteepRock`]: rock where `up < up_below`, or the roughness is over a threshold;
//! 4. [`Feature`]: a material where the feature field plus jitter is over a threshold;
//! 5. [`Cover`]: one ground material, or [`Bands`] by height.

use super::features::{lerp, model_key, radial, ColumnDensity, ColumnModel, NoiseBatch, Scales};
use super::shading::{Look, MaterialMap};
use super::{EdgeVertices, PresetKind, Terrain};
use crate::noise::{derive_seed, gradient3};
use crate::terrain::TerrainSpec;
use pmc_geometry::glam::DVec3;
use std::sync::Arc;

/// What the material rules read of a column.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ground {
    /// Surface radius of the height field, before 3D displacement (metres).
    pub h: f64,
    /// How far overhangs move the surface there (metres).
    pub amp: f64,
    /// The planet's feature field in `[0, 1]` (dunes, maria), 0 where it has none.
    pub feature: f64,
    /// Roughness in `[0, 1]` (canyons, mountain belts), 0 where the planet has none.
    pub rough: f64,
}

impl Ground {
    /// The ground a fraction `t` of the way to `other`, every value interpolated.
    fn lerp(&self, other: &Ground, t: f64) -> Ground {
        Ground {
            h: lerp(self.h, other.h, t),
            amp: lerp(self.amp, other.amp, t),
            feature: lerp(self.feature, other.feature, t),
            rough: lerp(self.rough, other.rough, t),
        }
    }
}

/// A column model that the shared material rules can shade.
pub(crate) trait GroundModel: ColumnModel {
    /// The scales of the layout the model was built for.
    fn scales(&self) -> &Scales;
    /// The radius heights are measured from: the sea level, or the mean surface (metres).
    fn datum(&self) -> f64;
    /// What the rules read of `col`.
    fn ground(col: &Self::Column) -> Ground;
}

/// A planet's parameters of the shared rules. Lengths are in the units the presets size their
/// features in: voxel depths `l_d`, tiles, fractions of the shell thickness `T`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MaterialRules {
    /// Rock under the surface.
    pub cave: CaveRock,
    /// Ice or snow, if the planet has any.
    pub cap: Option<Cap>,
    /// Rock on steep slopes and rough ground.
    pub steep: SteepRock,
    /// A material where the feature field is strong, if the planet has one.
    pub feature: Option<Feature>,
    /// Everything else.
    pub cover: Cover,
    /// The salt of the jitter noise's seed ([`derive_seed`] of the planet's seed).
    pub jitter_salt: u64,
    /// The jitter noise's length, in tiles.
    pub jitter_tiles: f64,
    /// How far the jitter moves the height `z` that the snow line and the bands read, as a
    /// fraction of `T` per unit of noise (0 where no rule reads it).
    pub height_jitter: f64,
    /// Where a chunk's vertices take their columns from.
    pub vertices: VertexColumns,
}

/// Cave rock: deeper under the column's surface than `max(depth, amp + margin)`, `amp` the
/// overhang amplitude (depths in `l_d`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CaveRock {
    /// The material.
    pub id: u8,
    /// The least depth (`l_d`).
    pub depth: f64,
    /// The depth beyond the overhang amplitude (`l_d`).
    pub margin: f64,
}

/// Ice or snow on flat ground (`up > flat`) beyond a line.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cap {
    /// The material.
    pub id: u8,
    /// The least `up` of the ground it covers.
    pub flat: f64,
    /// Where it begins.
    pub line: CapLine,
}

/// Where a [`Cap`] begins.
#[derive(Clone, Copy, Debug)]
pub(crate) enum CapLine {
    /// Poleward of a latitude, whatever the height: `|sin lat| + jitter j > from`.
    Polar {
        /// The sine of the latitude where it begins.
        from: f64,
        /// The jitter's weight.
        jitter: f64,
    },
    /// Above a snow line falling towards the poles: `z > max(T (equator - fall sin^2 lat),
    /// floor T)`.
    SnowLine {
        /// The snow line at the equator (fraction of `T`).
        equator: f64,
        /// How far it falls from the equator to the poles (fraction of `T`).
        fall: f64,
        /// The lowest it goes (fraction of `T`).
        floor: f64,
    },
}

/// Rock where `up < up_below`, or the roughness is over `rough_above`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SteepRock {
    /// The material.
    pub id: u8,
    /// The `up` under which the ground is steep.
    pub up_below: f64,
    /// The roughness over which the ground is rock whatever its slope, if any.
    pub rough_above: Option<f64>,
}

/// A material where the feature field plus `jitter j` is over `above`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Feature {
    /// The material.
    pub id: u8,
    /// The threshold.
    pub above: f64,
    /// The jitter's weight.
    pub jitter: f64,
}

/// What covers the ground that no earlier rule claims.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Cover {
    /// One material everywhere.
    Bare(u8),
    /// Bands by height.
    Bands(Bands),
}

/// Bands by the height `z` above the datum (fractions of `T`): the shore, lowlands of woods and
/// open ground by a noise, woods up to a tree line (bare on rough ground high up), rock above.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bands {
    /// The shore's material, below `shore_below`.
    pub shore: u8,
    /// The top of the shore.
    pub shore_below: f64,
    /// The top of the lowlands: woods where the woods noise is over `woods_above`, open ground
    /// elsewhere.
    pub lowland_below: f64,
    /// The woods' material.
    pub woods: u8,
    /// The open ground's material.
    pub open: u8,
    /// The woods noise's threshold in the lowlands.
    pub woods_above: f64,
    /// The salt of the woods noise's seed ([`derive_seed`] of the planet's seed).
    pub woods_salt: u64,
    /// The woods noise's length, in tiles.
    pub woods_tiles: f64,
    /// The tree line: woods up to it, except on ground rougher than `bare_rough` above
    /// `bare_above`.
    pub tree_line: f64,
    /// The height above which rough ground is bare.
    pub bare_above: f64,
    /// The roughness over which ground above `bare_above` is bare.
    pub bare_rough: f64,
    /// The material above the tree line and of bare ground.
    pub high: u8,
}

/// Where a chunk's vertices take the columns they are shaded with ([`Shader::shade_edges`]).
///
/// [`Shader::shade_edges`]: super::Shader::shade_edges
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum VertexColumns {
    /// The column along the vertex's own direction.
    Own,
    /// The columns at the two ends of the vertex's edge, interpolated at the vertex: those the
    /// density batch kept, or computed once per direction.
    EdgeEnds,
}

/// The shared rules over a column model: a [`MaterialMap`] whose batches compute the columns
/// ([`ColumnModel::columns`]) and the noises over all the points at once.
struct ColumnMaterials<M> {
    model: Arc<M>,
    rules: MaterialRules,
    jitter_seed: u64,
    jitter_len: f64,
    /// The woods noise's seed and frequency, where the bands read it.
    woods: Option<(u64, f64)>,
}

impl<M: GroundModel> ColumnMaterials<M> {
    /// The rules `rules` over `model`, for a planet of `seed`.
    fn new(model: Arc<M>, rules: MaterialRules, seed: u64) -> Self {
        let s = *model.scales();
        let woods = match rules.cover {
            Cover::Bands(b) => Some((derive_seed(seed, b.woods_salt), s.freq(b.woods_tiles * s.tile))),
            Cover::Bare(_) => None,
        };
        ColumnMaterials {
            model,
            rules,
            jitter_seed: derive_seed(seed, rules.jitter_salt),
            jitter_len: rules.jitter_tiles * s.tile,
            woods,
        }
    }

    /// The material at radius `r` along `dir`, normal `normal`, over ground `g`, with the jitter
    /// and woods noises there (each read at most once, and only where a rule needs it).
    fn material_in(
        &self,
        g: &Ground,
        r: f64,
        dir: DVec3,
        normal: DVec3,
        jitter: impl FnOnce() -> f64,
        woods: impl FnOnce() -> f64,
    ) -> u8 {
        let (rules, s) = (&self.rules, self.model.scales());
        let (t, l_d) = (s.thickness, s.l_d);
        let cave = &rules.cave;
        if g.h - r > (cave.depth * l_d).max(g.amp + cave.margin * l_d) {
            return cave.id;
        }
        let j = jitter();
        let up = normal.dot(dir);
        let z = r - self.model.datum() + rules.height_jitter * t * j;
        if let Some(cap) = &rules.cap {
            let beyond = match cap.line {
                CapLine::Polar { from, jitter } => dir.y.abs() + jitter * j > from,
                CapLine::SnowLine { equator, fall, floor } => z > (t * (equator - fall * dir.y * dir.y)).max(floor * t),
            };
            if beyond && up > cap.flat {
                return cap.id;
            }
        }
        let steep = &rules.steep;
        if up < steep.up_below || steep.rough_above.is_some_and(|a| g.rough > a) {
            return steep.id;
        }
        if let Some(f) = &rules.feature {
            if g.feature + f.jitter * j > f.above {
                return f.id;
            }
        }
        match &rules.cover {
            Cover::Bare(id) => *id,
            Cover::Bands(b) => {
                if z < b.shore_below * t {
                    b.shore
                } else if z < b.lowland_below * t {
                    if woods() > b.woods_above {
                        b.woods
                    } else {
                        b.open
                    }
                } else if z < b.tree_line * t && !(g.rough > b.bare_rough && z > b.bare_above * t) {
                    b.woods
                } else {
                    b.high
                }
            }
        }
    }

    /// The materials at `points` (normals `normals`) over the grounds `grounds`, one per point,
    /// into `out` (cleared first); every noise over all the points at once.
    fn materials_over(&self, points: &[DVec3], normals: &[DVec3], grounds: &[Ground], out: &mut Vec<u8>) {
        let (radii, dirs): (Vec<f64>, Vec<DVec3>) = points.iter().map(|p| radial(*p)).unzip();
        // The jitter at every point (`0 + 1 n`: a negative zero becomes a positive one, which
        // changes no rule: the jitter is only added, scaled, to a value compared with a
        // threshold).
        let mut noise = NoiseBatch::default();
        noise.set_points(points.len(), |i| points[i] / self.jitter_len);
        let mut jitter = Vec::new();
        noise.values(self.jitter_seed, &mut jitter);
        // The woods noise, where the bands read it (only compared with a positive threshold).
        let mut woods = Vec::new();
        if let Some((seed, freq)) = self.woods {
            noise.set_points(dirs.len(), |i| dirs[i] * freq);
            noise.values(seed, &mut woods);
        }
        out.clear();
        out.extend(
            (0..points.len())
                .map(|i| self.material_in(&grounds[i], radii[i], dirs[i], normals[i], || jitter[i], || woods[i])),
        );
    }
}

impl<M: GroundModel> MaterialMap for ColumnMaterials<M> {
    fn material(&self, p: DVec3, normal: DVec3) -> u8 {
        let (r, dir) = radial(p);
        let g = M::ground(&self.model.column(dir));
        self.material_in(
            &g,
            r,
            dir,
            normal,
            || gradient3(p / self.jitter_len, self.jitter_seed),
            || {
                let (seed, freq) = self.woods.expect("only the bands read the woods noise");
                gradient3(dir * freq, seed)
            },
        )
    }

    /// One batch of columns ([`ColumnModel::columns`]) for all the points.
    fn materials(&self, points: &[DVec3], normals: &[DVec3], _on_surface: bool, out: &mut Vec<u8>) {
        assert_eq!(points.len(), normals.len(), "one normal per point");
        let dirs: Vec<DVec3> = points.iter().map(|p| radial(*p).1).collect();
        let mut cols = Vec::with_capacity(points.len());
        self.model.columns(&dirs, &mut cols);
        let grounds: Vec<Ground> = cols.iter().map(M::ground).collect();
        self.materials_over(points, normals, &grounds, out);
    }

    /// With [`VertexColumns::EdgeEnds`], the columns at the chunk's directions (the batch's, or
    /// those the edges name, computed once each), interpolated across the surface at the
    /// vertices of lateral edges.
    fn edge_materials(&self, v: &EdgeVertices<'_>, out: &mut Vec<u8>) {
        if self.rules.vertices == VertexColumns::Own {
            return self.materials(v.points, v.normals, false, out);
        }
        let computed;
        let kept = v.columns.get::<M::Column>(model_key(&self.model), v.dirs);
        let (cols, slot): (&[M::Column], Option<Vec<u32>>) = match kept {
            Some(cols) => (cols, None),
            None => {
                // Only the directions some edge ends at, each once.
                let mut slot = vec![u32::MAX; v.dirs.len()];
                let mut used = Vec::new();
                for e in v.edges {
                    for d in [e.a, e.b] {
                        if slot[d as usize] == u32::MAX {
                            slot[d as usize] = used.len() as u32;
                            used.push(v.dirs[d as usize]);
                        }
                    }
                }
                let mut cols = Vec::with_capacity(used.len());
                self.model.columns(&used, &mut cols);
                computed = cols;
                (&computed, Some(slot))
            }
        };
        let ground = |d: u32| {
            M::ground(match &slot {
                Some(slot) => &cols[slot[d as usize] as usize],
                None => &cols[d as usize],
            })
        };
        let at: Vec<Ground> = v
            .edges
            .iter()
            .map(|e| {
                let a = ground(e.a);
                if e.a == e.b {
                    a
                } else {
                    a.lerp(&ground(e.b), e.t)
                }
            })
            .collect();
        self.materials_over(v.points, v.normals, &at, out);
    }
}

/// The terrain of preset `kind` for `seed` over a column model: the model as the density, shaded
/// by the shared rules `rules` in the colours of `look`.
pub(crate) fn column_terrain<M: GroundModel>(
    kind: PresetKind,
    seed: u64,
    model: Arc<M>,
    sea_radius: Option<f64>,
    look: &Look,
    rules: MaterialRules,
) -> Terrain {
    let tile = model.scales().tile;
    let map = ColumnMaterials::new(model.clone(), rules, seed);
    let density = Arc::new(ColumnDensity(model));
    look.terrain(TerrainSpec::preset(kind, seed), density, sea_radius, map, tile)
}
