//! The measured per-level geometric errors.

use pmc_geometry::Layout;
use pmc_lod::bounds::LIPSCHITZ;
use pmc_lod::measure_level_errors;
use pmc_planet::{Planet, PresetKind};

fn assert_table(errors: &[f64], layout: &Layout) {
    assert_eq!(errors.len(), usize::from(layout.max_level()) + 1);
    assert_eq!(errors[0], 0.0);
    assert!(errors.iter().all(|e| e.is_finite() && *e >= 0.0), "{errors:?}");
    assert!(errors.windows(2).all(|w| w[0] <= w[1]), "not monotone: {errors:?}");
}

#[test]
fn every_preset_gives_a_finite_monotone_table() {
    let layout = Layout::default();
    for preset in PresetKind::ALL {
        let planet = Planet::new(preset, 4, layout);
        let errors = measure_level_errors(&planet, 48, 9);
        assert_table(&errors, &layout);
        assert!(errors[1] > 0.0, "{preset}: {errors:?}");
        assert_eq!(
            errors,
            measure_level_errors(&planet, 48, 9),
            "{preset}: not deterministic"
        );
    }
}

#[test]
fn relief_costs_far_more_than_a_smooth_sphere() {
    let layout = Layout::default();
    let sphere = measure_level_errors(&Planet::new(PresetKind::Sphere, 1, layout), 64, 3);
    let earth = measure_level_errors(&Planet::new(PresetKind::Earthlike, 1, layout), 64, 3);
    assert_table(&sphere, &layout);
    assert_table(&earth, &layout);
    for level in 1..sphere.len() {
        assert!(
            5.0 * sphere[level] < earth[level],
            "level {level}: sphere {} m, earthlike {} m",
            sphere[level],
            earth[level]
        );
    }
}

/// On the exact sphere the error is the sagitta of a cell's flat triangles: below the sagitta
/// of the widest cell diagonal, and growing about fourfold per level (quadratic in the cell
/// size).
#[test]
fn the_sphere_measures_its_chord_sagitta() {
    let layout = Layout::default();
    let planet = Planet::new(PresetKind::Sphere, 1, layout);
    let errors = measure_level_errors(&planet, 64, 5);
    let r = layout.radius();
    for level in 1..errors.len() {
        let theta = LIPSCHITZ * std::f64::consts::SQRT_2 * f64::from(2u32 << level) / layout.face_tiles() as f64;
        let bound = r * (1.0 - (0.5 * theta).cos());
        assert!(
            errors[level] > 0.0 && errors[level] <= bound,
            "level {level}: {} vs {bound}",
            errors[level]
        );
        if level > 1 {
            let ratio = errors[level] / errors[level - 1];
            assert!((2.5..6.0).contains(&ratio), "level {level}: ratio {ratio}");
        }
    }
}

/// The earth preset at true scale (radius 6 371 km, 19 levels) misses kilometres of relief on its
/// coarsest levels, and the measurement sees it.
///
/// The relief (see `pmc_density::presets::earth`): ocean floors 2.9 to 5.5 km below the sea and
/// trenches down to about 10 km, in arcs about 300 km wide; mountain belts about 800 km wide
/// whose ridges, 150 km across down to 25 m, reach 9.5 km; continental slopes from the shelf
/// down to the abyss, between continent cells about 5 500 km across. From level 15 on a cell is
/// 2^15 tiles (about 40 km) across, 2^18 tiles (about 310 km) on level 18, and a single cell
/// spans the whole 32.8 km shell in depth, so the level's surface is the bilinear interpolation
/// of heights between columns that far apart: it cuts through ridges and trenches narrower than
/// a cell and straight across slopes that bend inside one. Belts, trenches and slopes cover well
/// over 1% of the planet and the interpolation misses a good part of their relief there, so the
/// 99th percentile is at least several hundred metres on levels 15 to 18 (bound: 300 m) and
/// kilometres on level 18 (bound: 1 km).
#[test]
fn the_earths_coarsest_levels_miss_kilometres_of_relief() {
    let layout = PresetKind::Earth.default_layout(None).unwrap();
    assert_eq!(layout.max_level(), 18);
    let planet = Planet::new(PresetKind::Earth, 1, layout);
    let errors = measure_level_errors(&planet, 256, 7);
    assert_table(&errors, &layout);
    for level in 15..=18 {
        assert!(errors[level] >= 300.0, "level {level}: {errors:?}");
    }
    assert!(errors[18] >= 1000.0, "{errors:?}");
    // Level 1 cells are 2 m: its error is metres at most (rocks, cliffs and caves of a few
    // voxels), far below the coarse levels'.
    assert!(errors[1] > 0.0 && errors[1] < 10.0, "{errors:?}");
}

/// A level whose estimate settled (its two halves agreed) before the cap stops there: a larger
/// cap gives the same table, bit for bit.
#[test]
fn settled_levels_ignore_a_larger_cap() {
    let layout = Layout::default();
    for preset in [PresetKind::Sphere, PresetKind::Earthlike] {
        let planet = Planet::new(preset, 2, layout);
        let capped = measure_level_errors(&planet, 4096, 11);
        assert_table(&capped, &layout);
        assert_eq!(capped, measure_level_errors(&planet, 1 << 20, 11), "{preset}");
    }
}

#[test]
fn degenerate_requests_give_a_flat_table() {
    let layout = Layout::new(4, 4, 100.0, 1.0, 4).unwrap();
    let planet = Planet::new(PresetKind::Moon, 2, layout);
    assert_eq!(measure_level_errors(&planet, 0, 1), vec![0.0; 3]);
    let odd = Layout::new(4, 5, 100.0, 1.0, 2).unwrap();
    assert_eq!(
        measure_level_errors(&Planet::new(PresetKind::Earthlike, 2, odd), 32, 1),
        vec![0.0]
    );
    let small = measure_level_errors(&planet, 16, 1);
    assert_table(&small, &layout);
}
