//! The flight benchmark's harness: stops converge with every drawn chunk served, coarse views
//! draw coarse levels, and flying the same stop again is answered from the cache.

use crate::common::small_config;
use pmc_server::flight::{descent, fly, FlightCamera};
use pmc_server::AppState;

#[tokio::test]
async fn a_descent_converges_from_coarse_to_fine() {
    let state = AppState::new(small_config()).unwrap();
    let planet = state.default_planet().await.unwrap();
    let heights: Vec<(String, f64)> = [("orbit", 600.0), ("30 m", 30.0), ("2 m", 2.0), ("2 m again", 2.0)]
        .iter()
        .map(|(n, h)| (n.to_string(), *h))
        .collect();
    let stops = descent(&planet, 20.0, 30.0, &heights).unwrap();
    let camera = FlightCamera {
        max_pixel_error: 1.0,
        ..FlightCamera::default()
    };
    let reports = fly(&state, &stops, &camera).await.unwrap();
    assert_eq!(reports.len(), 4);
    for r in &reports {
        assert!(r.drawn_per_level.iter().sum::<usize>() > 0, "{}: nothing drawn", r.name);
        assert!(r.triangles > 0, "{}", r.name);
        assert!(r.converged >= r.selection);
        assert!(!r.truncated);
    }
    let finest = |r: &pmc_server::flight::StopReport| r.drawn_per_level.iter().position(|n| *n > 0).unwrap();
    assert!(
        finest(&reports[0]) >= finest(&reports[2]),
        "orbit finer than the ground"
    );
    assert_eq!(finest(&reports[2]), 0, "the ground view reaches level 0");
    // The same stop again: every chunk is cached, none generated.
    assert!(
        reports[3].chunks_per_second.iter().all(Option::is_none),
        "{:?}",
        reports[3].chunks_per_second
    );
    assert_eq!(reports[3].triangles, reports[2].triangles);
    assert!(descent(&planet, 95.0, 0.0, &heights).is_err());
}
