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
