//! Vulkan objects free themselves: setup that fails half-way leaves nothing
//! behind, and the validation layer (which lists every object still alive
//! when the device is destroyed) would say so if it did.
mod common;

use common::validating_gpu;

use ash::vk;
use isr::renderer::Renderer;
use isr::scene::cornell::cornell_box;
use isr::settings::{Method, RenderSettings};
use isr::vk::pipeline::fail_pipeline_creation_after;
use isr::vk::Gpu;

/// Drops `gpu` (it must be the device's last holder, so the device really is
/// destroyed) and returns what the layer reported meanwhile.
fn destroy(gpu: Gpu) -> Vec<String> {
    let log = gpu.validation_log().expect("validation is on");
    assert_eq!(
        std::sync::Arc::strong_count(&gpu.shared),
        1,
        "something still holds the device"
    );
    drop(gpu);
    log.take()
}

#[test]
fn a_renderer_failing_at_any_pipeline_frees_everything_it_made() {
    let settings = RenderSettings {
        width: 64,
        height: 48,
        rsm_resolution: 32,
        method: Method::new("isr"),
        ..Default::default()
    }
    .with(&isr::methods::vpls::VPLS, 16)
    .with(&isr::methods::isr::BASE, 8);
    // The built-in spot, and a point light with a directional one: the cube
    // RSM (`rsm-cube`) and `light-sum` make pipelines and images of their own.
    let spot = cornell_box();
    let mut several = cornell_box();
    let base = several.lights[0];
    several.lights = vec![
        isr::scene::Light {
            kind: isr::scene::LightKind::Point,
            position: glam::Vec3::new(0.3, 1.3, 0.2),
            ..base
        },
        isr::scene::Light {
            kind: isr::scene::LightKind::Directional,
            direction: glam::Vec3::new(0.4, -1.0, -0.3).normalize(),
            ..base
        },
    ];
    for scene in [spot, several] {
        made_pipelines_fail_in_turn(&scene, &settings);
    }
}

fn made_pipelines_fail_in_turn(scene: &isr::scene::Scene, settings: &RenderSettings) {
    let mut failures = 0;
    for n in 0..18 {
        let gpu = validating_gpu();
        fail_pipeline_creation_after(Some(n));
        let failed = match Renderer::new(&gpu, scene, settings) {
            Err(e) => Some(format!("{e:#}")),
            // Past the last pipeline: setup succeeds and is dropped normally.
            Ok(_) => None,
        };
        fail_pipeline_creation_after(None);
        if let Some(e) = failed {
            assert!(e.contains("failure injected"), "{e}");
            failures += 1;
        }
        let messages = destroy(gpu);
        assert!(
            messages.is_empty(),
            "failing pipeline {n} left objects behind:\n{}",
            messages.join("\n")
        );
    }
    assert!(failures >= 8, "only {failures} pipelines were made");
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
