//! Vulkan objects free themselves: setup that fails half-way leaves nothing
//! behind, and the validation layer (which lists every object still alive
//! when the device is destroyed) would say so if it did. For every method,
//! each of the pipelines its setup makes is made to fail in turn
//! (`isr::vk::pipeline::pipelines_created` counts them).
mod common;

use ash::vk;
use common::*;
use isr::renderer::Renderer;
use isr::scene::{cornell::cornell_box, Scene};
use isr::settings::RenderSettings;
use isr::vk::pipeline::{fail_pipeline_creation_after, pipelines_created};

/// Drops `gpu` (it must be the device's last holder, so the device really is
/// destroyed) and returns what the layer reported meanwhile.
fn destroy(gpu: TestGpu) -> Vec<String> {
    let log = gpu.validation_log().expect("validation is on");
    assert_eq!(
        std::sync::Arc::strong_count(&gpu.shared),
        1,
        "something still holds the device"
    );
    drop(gpu);
    log.take()
}

/// `method` at a tiny size, with the parameters it reads that set its cost
/// small (and no others).
fn tiny(method: &'static str) -> RenderSettings {
    small_params(sized(method, 32, 24, 32), 16, 8, 32 * 24 * 64)
}

/// Makes the renderer of `scene` once to count the pipelines its setup
/// makes (N), then makes pipeline 0, 1, ..., N - 1 fail in turn: every one
/// must fail setup with the injected error and leave no object alive when
/// the device goes; with N pipelines allowed, setup succeeds. Returns N.
fn each_pipeline_fails_in_turn(label: &str, scene: &Scene, settings: &RenderSettings) -> u64 {
    let gpu = validating_gpu();
    let before = pipelines_created();
    drop(Renderer::new(&gpu, scene, settings).unwrap_or_else(|e| panic!("{label}: {e:#}")));
    let n = pipelines_created() - before;
    let messages = destroy(gpu);
    assert!(messages.is_empty(), "{label}: {messages:?}");
    assert!(n > 0, "{label}: no pipelines were made");
    for k in 0..=n {
        let gpu = validating_gpu();
        fail_pipeline_creation_after(Some(k as u32));
        // Past the last pipeline, setup succeeds and is dropped normally.
        let failed = Renderer::new(&gpu, scene, settings).err();
        fail_pipeline_creation_after(None);
        match failed {
            Some(e) => assert!(
                k < n && format!("{e:#}").contains("failure injected"),
                "{label}: failing pipeline {k} of {n}: {e:#}"
            ),
            None => assert_eq!(k, n, "{label}: pipeline {k} of {n} was never made"),
        }
        let messages = destroy(gpu);
        assert!(
            messages.is_empty(),
            "{label}: failing pipeline {k} of {n} left objects behind:\n{}",
            messages.join("\n")
        );
    }
    println!("{label}: each of {n} pipelines failed in turn");
    n
}

/// One test per method (they run side by side: the hook is per thread).
macro_rules! every_method {
    ($($test:ident: $method:literal,)*) => {
        $(
            #[test]
            fn $test() {
                each_pipeline_fails_in_turn($method, &cornell_box(), &tiny($method));
            }
        )*

        #[test]
        fn every_registered_method_is_covered() {
            let covered = [$($method),*];
            for d in isr::methods::REGISTRY {
                assert!(covered.contains(&d.key().name()), "{} has no test here", d.key());
            }
        }
    };
}

every_method! {
    none_fails_at_every_pipeline: "none",
    rsm_gather_fails_at_every_pipeline: "rsm-gather",
    rsm_splat_fails_at_every_pipeline: "rsm-splat",
    rsm_splat_restricted_fails_at_every_pipeline: "rsm-splat-restricted",
    multires_splat_fails_at_every_pipeline: "multires-splat",
    multires_gather_fails_at_every_pipeline: "multires-gather",
    isr_fails_at_every_pipeline: "isr",
    hisr_fails_at_every_pipeline: "hisr",
    lpv_fails_at_every_pipeline: "lpv",
    vct_fails_at_every_pipeline: "vct",
    reference_fails_at_every_pipeline: "reference",
}

/// A point light with a directional one: the cube RSM (`rsm-cube`) and
/// `light-sum` make pipelines and images of their own.
#[test]
fn two_lights_fail_at_every_pipeline() {
    let scene = cornell_with(vec![box_point(), box_sun()]);
    let spot = each_pipeline_fails_in_turn("isr, spot", &cornell_box(), &tiny("isr"));
    let two = each_pipeline_fails_in_turn("isr, point + directional", &scene, &tiny("isr"));
    assert!(
        two > spot,
        "{two} pipelines with two lights, {spot} with one spot"
    );
}

/// Silence means something only if the layer reports a leak.
#[test]
fn the_layer_reports_an_object_left_alive() {
    let gpu = validating_gpu();
    let info = vk::BufferCreateInfo::default()
        .size(256)
        .usage(vk::BufferUsageFlags::STORAGE_BUFFER);
    let leaked = unsafe { gpu.device.create_buffer(&info, None) }.unwrap();
    assert_ne!(leaked, vk::Buffer::null());
    let messages = destroy(gpu);
    assert!(
        messages.iter().any(|m| m.contains("VkBuffer")),
        "expected a report of the undestroyed buffer, got: {messages:?}"
    );
}
