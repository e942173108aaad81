//! What `Renderer::render_frames` returns: every frame's per-pass numbers,
//! which of them counted (`Profiler`'s counting frames) and which timed.

use crate::vk::profiler::PassSample;

/// GPU numbers of every frame rendered, and the CPU-measured wall time of each.
#[derive(Clone, Debug, Default)]
pub struct FrameStats {
    /// Every frame's passes, in the order the frames finished.
    pub frames: Vec<Vec<PassSample>>,
    /// Per frame: whether it held the statistics and occlusion queries (a
    /// counting frame, `Profiler`), whose times are left out when a run has
    /// frames that only timed.
    pub counted: Vec<bool>,
    /// Per frame, from its first submission to the moment its fence was seen
    /// signalled: at least its GPU time, more when it waited behind the frame
    /// before it.
    pub wall_ms: Vec<f64>,
    /// From the first submission to the last frame's completion.
    pub elapsed_ms: f64,
    /// Multiresolution patches per level of the last frame, when it counted
    /// (`None` without a multiresolution buffer or a counting last frame).
    pub patches_per_level: Option<Vec<u32>>,
}

impl FrameStats {
    /// Median over frames of the summed time of all passes, or of the passes
    /// that exist only for indirect light; `None` without timestamps.
    pub fn gpu_ms_median(&self, indirect_only: bool) -> Option<f64> {
        median(&self.gpu_ms_sums(indirect_only))
    }

    /// The least over frames of the same sums: on a shared or loaded
    /// machine, the least disturbed frame.
    pub fn gpu_ms_min(&self, indirect_only: bool) -> Option<f64> {
        self.gpu_ms_sums(indirect_only).into_iter().reduce(f64::min)
    }

    /// Appends the frames of a later call (the run goes on).
    pub fn extend(&mut self, later: FrameStats) {
        self.frames.extend(later.frames);
        self.counted.extend(later.counted);
        self.wall_ms.extend(later.wall_ms);
        if later.patches_per_level.is_some() {
            self.patches_per_level = later.patches_per_level;
        }
    }

    /// The frames whose times count: those that only timed, or every frame
    /// when all of them counted (a one-frame run).
    pub fn timed(&self) -> impl Iterator<Item = &Vec<PassSample>> + '_ {
        self.frames
            .iter()
            .zip(self.timed_mask())
            .filter(|&(_, t)| t)
            .map(|(f, _)| f)
    }

    /// The wall times of the frames [`Self::timed`] yields.
    pub fn timed_wall_ms(&self) -> Vec<f64> {
        self.wall_ms
            .iter()
            .zip(self.timed_mask())
            .filter(|&(_, t)| t)
            .map(|(&ms, _)| ms)
            .collect()
    }

    /// Per frame, whether its times count (`frames`, `counted` and
    /// `wall_ms` run in step).
    fn timed_mask(&self) -> impl Iterator<Item = bool> + '_ {
        debug_assert_eq!(self.frames.len(), self.counted.len());
        let any_timing = self.counted.iter().any(|&c| !c);
        self.counted.iter().map(move |&c| !(any_timing && c))
    }

    /// The passes of the last counting frame: their fragment and invocation
    /// counts (the times of every pass are in [`Self::timed`]).
    pub fn counts(&self) -> Option<&[PassSample]> {
        self.frames
            .iter()
            .zip(&self.counted)
            .rev()
            .find(|&(_, &c)| c)
            .map(|(f, _)| f.as_slice())
    }

    fn gpu_ms_sums(&self, indirect_only: bool) -> Vec<f64> {
        self.timed()
            .filter_map(|f| {
                f.iter()
                    .filter(|p| !indirect_only || p.kind.indirect)
                    .map(|p| p.gpu_ms)
                    .try_fold(0.0, |acc, ms| Some(acc + ms?))
            })
            .collect()
    }
}

/// The median of `values` (the mean of the middle two for an even count);
/// `None` when empty. Here, beside the frame numbers it summarizes, so that
/// `FrameStats` needs nothing from `report`, which builds on it.
pub fn median(values: &[f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn median_of_odd_even_and_empty() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
