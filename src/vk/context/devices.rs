//! The physical devices the loader reports, what each is, and why one cannot
//! run isr.

use super::*;

pub(super) fn describe(
    instance: &ash::Instance,
    index: usize,
    pd: vk::PhysicalDevice,
) -> DeviceInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    unsafe { instance.get_physical_device_properties2(pd, &mut props2) };
    let p = props2.properties;
    let v = p.api_version;
    let api_version = (
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v),
    );
    let name = p
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let driver_name = driver
        .driver_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let driver_info = driver
        .driver_info_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let unusable = unusable_reason(instance, pd, p);
    DeviceInfo {
        index,
        name,
        kind: p.device_type,
        driver: format!("{driver_name} {driver_info}").trim().to_string(),
        api_version,
        unusable,
    }
}

pub(super) fn graphics_queue_family(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
) -> Option<u32> {
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    families
        .iter()
        .position(|f| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        })
        .map(|i| i as u32)
}

pub(super) fn unusable_reason(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    p: vk::PhysicalDeviceProperties,
) -> Option<String> {
    if p.api_version < vk::API_VERSION_1_3 {
        return Some(format!(
            "supports Vulkan {}.{} only; isr needs 1.3",
            vk::api_version_major(p.api_version),
            vk::api_version_minor(p.api_version)
        ));
    }
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
    unsafe { instance.get_physical_device_features2(pd, &mut f2) };
    if f13.dynamic_rendering == vk::FALSE || f13.synchronization2 == vk::FALSE {
        return Some("lacks dynamicRendering or synchronization2".into());
    }
    if graphics_queue_family(instance, pd).is_none() {
        return Some("has no graphics+compute queue".into());
    }
    None
}

pub(super) fn type_rank(kind: vk::PhysicalDeviceType) -> u32 {
    match kind {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    }
}

/// Every physical device the loader reports, in the loader's order (the index
/// `--device` takes).
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let entry = load_entry()?;
    let instance = create_instance(&entry, false)?;
    let devices = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
    let infos = devices
        .iter()
        .enumerate()
        .map(|(i, &pd)| describe(&instance, i, pd))
        .collect();
    unsafe { instance.destroy_instance(None) };
    Ok(infos)
}
