//! The light volume's progressive build
//! ([`super::LightVolumePass::set_progressive`]): one batch of photons a
//! frame, folded into the sums by [`progressive_weight`].

use super::{LightVolumePass, STEP_STRIDE};

/// The weight of a progressive frame's batch in the sums (what they keep
/// is one less it), `since_change` batches after the last change, whose
/// exact mean starts `mean_from` batches after it, in a full count of
/// `window` batches: before `mean_from` a running mean over `window`
/// batches, from it the mean of the batches since.
fn progressive_weight(since_change: u32, mean_from: u32, window: u32) -> f32 {
    if since_change >= mean_from {
        1.0 / (since_change - mean_from + 1) as f32
    } else {
        1.0 / window.max(1) as f32
    }
}

impl LightVolumePass {
    /// One progressive frame ([`Self::set_progressive`]): when the volume
    /// is stale, the cells' extinction anew and the batches to come; while
    /// batches are to come, one, folded into the sums by
    /// [`progressive_weight`], and the planes.
    pub(super) fn build_progressively(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        group0_layout: &wgpu::BindGroupLayout,
        group0: &wgpu::BindGroup,
        constants: &[(&str, f64)],
    ) {
        let window = self.batch_count().max(1);
        let fresh = self.stale;
        if fresh {
            self.stale = false;
            self.builds += 1;
            // A new volume: the mean of its first `window` batches. A
            // change: a running mean over `window` batches that follows
            // the clouds while they keep changing, then, once they rest,
            // the exact mean of `window` batches of the new light alone.
            self.mean_from = if self.traced == 0 { 0 } else { window };
            self.since_change = 0;
            self.pending = self.mean_from + window;
        }
        if self.pending == 0 {
            return;
        }
        let Some(&(_, batch)) = self.batches.first() else {
            return;
        };
        let total = self.batches.iter().map(|b| b.1).sum::<u32>();
        // Each batch's tracks scaled to the full count's.
        let w = progressive_weight(self.since_change, self.mean_from, window);
        let gain = w * total as f32 / batch as f32;
        queue.write_buffer(
            &self.fold,
            0,
            bytemuck::cast_slice(&[1.0 - w, gain, 0.0, 0.0]),
        );
        let first = self.traced.wrapping_mul(batch);
        let entry: [u32; 4] = [first, batch, total, 0];
        let last = self.batches.len() as u64 * STEP_STRIDE;
        queue.write_buffer(&self.steps, last, bytemuck::bytes_of(&entry));
        self.traced += 1;
        self.since_change += 1;
        self.pending -= 1;
        let entry = (last as u32, batch);
        self.record(
            device,
            queue,
            (group0_layout, group0),
            constants,
            (false, fresh),
            &[entry],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_progressive_volume_forgets_the_light_before_a_change() {
        // The share of the sums from before the change after each batch:
        // it falls while the running mean follows and is 0 once the exact
        // mean starts; a fresh volume's first batch keeps nothing.
        let window = 16;
        assert_eq!(progressive_weight(0, 0, window), 1.0);
        let mut old = 1.0f32;
        for k in 0..2 * window {
            let w = progressive_weight(k, window, window);
            old *= 1.0 - w;
            if k < window {
                assert!(old > 0.0 && old < 1.0);
            }
        }
        assert_eq!(old, 0.0);
        // The exact mean: every batch after `mean_from` weighs the same.
        let mut shares = vec![];
        for k in window..2 * window {
            let w = progressive_weight(k, window, window);
            shares.iter_mut().for_each(|s: &mut f32| *s *= 1.0 - w);
            shares.push(w);
        }
        for s in &shares {
            assert!((s - 1.0 / window as f32).abs() < 1e-6, "{shares:?}");
        }
    }
}
