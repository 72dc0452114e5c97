//! Tests of `light_volume_pass.rs`: the folded dispatches and the batches.

use super::*;

#[test]
fn folded_dispatches_cover_every_invocation() {
    for n in [
        1,
        63,
        64,
        65,
        4096 * 64,
        4096 * 64 + 1,
        1_769_472,
        16_257_024,
    ] {
        let (x, y) = workgroups(n);
        assert!(x <= 65_535 && y <= 65_535);
        // `light_invocation`: id.x + id.y · ROW · 64 reaches n - 1.
        assert!(
            (x * LIGHT_WORKGROUP - 1) + (y - 1) * ROW * LIGHT_WORKGROUP >= n - 1,
            "{n}"
        );
    }
}

#[test]
fn the_batches_cover_every_photon_once() {
    for (photons, batch) in [(0, 64), (1, 64), (640, 64), (641, 64), (1000, 1)] {
        let b = batches(photons, batch);
        let mut next = 0;
        for (first, count) in &b {
            assert_eq!(*first, next);
            assert!(*count >= 1 && *count <= batch);
            next += count;
        }
        assert_eq!(next, photons);
    }
}
