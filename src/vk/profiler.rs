//! Named GPU timing scopes: a timestamp around every pass, plus a
//! pipeline-statistics query and an occlusion query in counting frames (see
//! below), and a debug label.
//!
//! Timing model. Lavapipe (Mesa 22.3) bins the commands of one command buffer,
//! so a timestamp written just *before* a pass reads close to that pass's *end*.
//! Differences between consecutive *end-of-pass* timestamps do add up to the
//! frame's wall time. So the frame writes one timestamp at its start and one
//! after each pass, and a pass's time is the difference to the previous one.
//! On a tiling or immediate GPU this is the same as begin/end pairs, minus
//! bubbles between passes (which are charged to the following pass).
//!
//! Fragment counts. Lavapipe's FRAGMENT_SHADER_INVOCATIONS counts every
//! rasterized block, stencil- and depth-rejected ones included, so the occlusion
//! query (`samples_passed`) is what counts fragments that pass the tests.
//!
//! Counting frames. The pipeline-statistics and occlusion queries cost time of
//! their own: on lavapipe about 0.15 ms per pass at 128x128 (a frame of HISR's
//! 12 passes took 9.8 ms with them and 7.9 ms without, medians of 6 runs). That
//! would bill every method for its number of passes rather than for its work.
//! So a frame either counts (timestamps, statistics and occlusion queries
//! around every pass) or only times (timestamps around every pass); a run's
//! last frame counts and its times come from the others
//! (`FrameStats::timed`).

use super::context::Shared;
use super::Gpu;
use anyhow::Result;
use ash::vk;
use std::sync::Arc;

/// What kind of work a pass does, for the queries it can hold and the
/// "indirect time" sum (docs/algorithm.md section 6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassKind {
    /// Draws inside a render-pass instance (occlusion queries are meaningful).
    pub graphics: bool,
    /// Exists only for indirect light.
    pub indirect: bool,
}

/// One pass's numbers from one frame.
#[derive(Clone, Debug)]
pub struct PassSample {
    pub name: &'static str,
    pub kind: PassKind,
    pub gpu_ms: Option<f64>,
    pub fragment_invocations: Option<u64>,
    pub compute_invocations: Option<u64>,
    pub samples_passed: Option<u64>,
}

pub struct Profiler {
    capacity: u32,
    timestamps: Option<vk::QueryPool>,
    statistics: Option<vk::QueryPool>,
    occlusion: vk::QueryPool,
    precise_occlusion: bool,
    timestamp_mask: u64,
    ns_per_tick: f64,
    passes: Vec<(&'static str, PassKind)>,
    /// Whether the frame being recorded (or last read) holds the statistics
    /// and occlusion queries.
    counting: bool,
    /// Appended to pass names as `name[label]` while set: which light view
    /// a pass belongs to when a frame has several.
    label: Option<String>,
    shared: Arc<Shared>,
}

/// `name[label]` as a `&'static str`: each distinct name is leaked once and
/// reused, so the set is bounded by passes times light views.
fn labelled(name: &'static str, label: &str) -> &'static str {
    use std::collections::HashSet;
    use std::sync::Mutex;
    static NAMES: Mutex<Option<HashSet<&'static str>>> = Mutex::new(None);
    let full = format!("{name}[{label}]");
    let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    let names = names.get_or_insert_with(HashSet::new);
    if let Some(&n) = names.get(full.as_str()) {
        return n;
    }
    let n: &'static str = Box::leak(full.into_boxed_str());
    names.insert(n);
    n
}

const STATISTICS: vk::QueryPipelineStatisticFlags = vk::QueryPipelineStatisticFlags::from_raw(
    vk::QueryPipelineStatisticFlags::FRAGMENT_SHADER_INVOCATIONS.as_raw()
        | vk::QueryPipelineStatisticFlags::COMPUTE_SHADER_INVOCATIONS.as_raw(),
);

impl Profiler {
    /// Room for `capacity` passes per frame.
    pub fn new(gpu: &Gpu, capacity: u32) -> Result<Self> {
        let create = |ty: vk::QueryType, count: u32, stats| unsafe {
            gpu.device.create_query_pool(
                &vk::QueryPoolCreateInfo::default()
                    .query_type(ty)
                    .query_count(count)
                    .pipeline_statistics(stats),
                None,
            )
        };
        let bits = unsafe {
            gpu.instance
                .get_physical_device_queue_family_properties(gpu.physical)
        }[gpu.queue_family as usize]
            .timestamp_valid_bits;
        let timestamp_mask = if bits >= 64 {
            u64::MAX
        } else {
            (1u64 << bits) - 1
        };
        // Pools are created into `out`, whose `Drop` frees them if a later one fails.
        let mut out = Self {
            capacity,
            timestamps: None,
            statistics: None,
            occlusion: vk::QueryPool::null(),
            precise_occlusion: gpu.features.precise_occlusion,
            timestamp_mask,
            ns_per_tick: gpu.properties.limits.timestamp_period as f64,
            passes: Vec::new(),
            counting: true,
            label: None,
            shared: gpu.shared.clone(),
        };
        if gpu.features.timestamps {
            out.timestamps = Some(create(
                vk::QueryType::TIMESTAMP,
                capacity + 1,
                vk::QueryPipelineStatisticFlags::empty(),
            )?);
        }
        if gpu.features.pipeline_statistics {
            out.statistics = Some(create(
                vk::QueryType::PIPELINE_STATISTICS,
                capacity,
                STATISTICS,
            )?);
        }
        out.occlusion = create(
            vk::QueryType::OCCLUSION,
            capacity,
            vk::QueryPipelineStatisticFlags::empty(),
        )?;
        Ok(out)
    }
    /// Resets the pools and writes the frame's first timestamp. A `counting`
    /// frame also holds the statistics and occlusion queries around every pass.
    pub fn begin_frame(&mut self, gpu: &Gpu, cmd: vk::CommandBuffer, counting: bool) {
        self.passes.clear();
        self.counting = counting;
        unsafe {
            if let Some(pool) = self.timestamps {
                gpu.device
                    .cmd_reset_query_pool(cmd, pool, 0, self.capacity + 1);
                gpu.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    pool,
                    0,
                );
            }
            if let Some(pool) = self.statistics {
                gpu.device.cmd_reset_query_pool(cmd, pool, 0, self.capacity);
            }
            gpu.device
                .cmd_reset_query_pool(cmd, self.occlusion, 0, self.capacity);
        }
    }

    /// Passes recorded from now on are named `name[label]` (`None`: `name`).
    pub fn set_label(&mut self, label: Option<String>) {
        self.label = label;
    }

    /// Records `body` as the pass `name`, surrounded by its queries and a debug
    /// label, followed by its end-of-pass timestamp.
    pub fn pass<R>(
        &mut self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        name: &'static str,
        kind: PassKind,
        body: impl FnOnce() -> R,
    ) -> R {
        let name = match &self.label {
            Some(l) => labelled(name, l),
            None => name,
        };
        let index = self.passes.len() as u32;
        assert!(
            index < self.capacity,
            "profiler capacity {} exceeded by pass {name}",
            self.capacity
        );
        self.passes.push((name, kind));
        let label = std::ffi::CString::new(name).unwrap_or_default();
        unsafe {
            if let Some(d) = &gpu.debug_device {
                d.cmd_begin_debug_utils_label(
                    cmd,
                    &vk::DebugUtilsLabelEXT::default().label_name(&label),
                );
            }
            if let Some(pool) = self.statistics.filter(|_| self.counting) {
                gpu.device
                    .cmd_begin_query(cmd, pool, index, vk::QueryControlFlags::empty());
            }
            if kind.graphics && self.counting {
                let flags = if self.precise_occlusion {
                    vk::QueryControlFlags::PRECISE
                } else {
                    vk::QueryControlFlags::empty()
                };
                gpu.device
                    .cmd_begin_query(cmd, self.occlusion, index, flags);
            }
        }
        let result = body();
        unsafe {
            if kind.graphics && self.counting {
                gpu.device.cmd_end_query(cmd, self.occlusion, index);
            }
            if let Some(pool) = self.statistics.filter(|_| self.counting) {
                gpu.device.cmd_end_query(cmd, pool, index);
            }
            if let Some(pool) = self.timestamps {
                gpu.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    pool,
                    index + 1,
                );
            }
            if let Some(d) = &gpu.debug_device {
                d.cmd_end_debug_utils_label(cmd);
            }
        }
        result
    }

    /// Whether the last frame begun holds the statistics and occlusion queries.
    pub fn counting(&self) -> bool {
        self.counting
    }

    /// Reads the last frame's queries. Call only after that frame's fence.
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<PassSample>> {
        let n = self.passes.len();
        let wait = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT;
        let mut times = vec![0u64; n + 1];
        if let Some(pool) = self.timestamps {
            unsafe {
                gpu.device
                    .get_query_pool_results(pool, 0, &mut times, wait)?
            };
        }
        let statistics = self.statistics.filter(|_| self.counting);
        let mut stats = vec![[0u64; 2]; n];
        if let Some(pool) = statistics {
            if n > 0 {
                unsafe {
                    gpu.device
                        .get_query_pool_results(pool, 0, &mut stats, wait)?
                };
            }
        }
        let mut samples = vec![0u64; n];
        for (i, (_, kind)) in self.passes.iter().enumerate() {
            if kind.graphics && self.counting {
                unsafe {
                    gpu.device.get_query_pool_results(
                        self.occlusion,
                        i as u32,
                        &mut samples[i..i + 1],
                        wait,
                    )?
                };
            }
        }
        let samples = self.passes.iter().enumerate().map(|(i, &(name, kind))| {
            let ticks = times[i + 1].wrapping_sub(times[i]) & self.timestamp_mask;
            PassSample {
                name,
                kind,
                gpu_ms: self
                    .timestamps
                    .map(|_| ticks as f64 * self.ns_per_tick * 1e-6),
                fragment_invocations: statistics.map(|_| stats[i][0]),
                compute_invocations: statistics.map(|_| stats[i][1]),
                samples_passed: (kind.graphics && self.counting).then_some(samples[i]),
            }
        });
        // A pass recorded several times in a row (the reference's chunks, one
        // per submission) is reported once, its numbers summed.
        let mut merged: Vec<PassSample> = Vec::new();
        for s in samples {
            match merged.last_mut() {
                Some(m) if m.name == s.name => {
                    let add = |a: Option<u64>, b: Option<u64>| a.zip(b).map(|(a, b)| a + b);
                    m.gpu_ms = m.gpu_ms.zip(s.gpu_ms).map(|(a, b)| a + b);
                    m.fragment_invocations = add(m.fragment_invocations, s.fragment_invocations);
                    m.compute_invocations = add(m.compute_invocations, s.compute_invocations);
                    m.samples_passed = add(m.samples_passed, s.samples_passed);
                }
                _ => merged.push(s),
            }
        }
        Ok(merged)
    }
}

impl Drop for Profiler {
    fn drop(&mut self) {
        let d = &self.shared.device;
        unsafe {
            for p in [self.timestamps.take(), self.statistics.take()]
                .into_iter()
                .flatten()
            {
                d.destroy_query_pool(p, None);
            }
            d.destroy_query_pool(self.occlusion, None);
        }
    }
}
