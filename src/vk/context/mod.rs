//! The Vulkan instance, device and queue, the allocator, and the validation-layer
//! log. Everything else borrows a [`Gpu`].

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_void, CStr};
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

mod devices;
mod fault;
mod submit;
pub use devices::list_devices;
use devices::*;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Help printed whenever no usable Vulkan driver is found.
pub const INSTALL_DRIVER_HINT: &str =
    "install a Vulkan driver: on Debian or Ubuntu without a GPU, \
     `sudo apt-get install mesa-vulkan-drivers libvulkan1` gives the lavapipe CPU driver \
     (or run `bash .ci/install-vulkan`); on a machine with a GPU, install its vendor's driver";

/// Whether to load the Khronos validation layer (with synchronization validation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    Off,
    /// On when the layer is installed, silently off otherwise (used by tests that
    /// are not about validation).
    IfInstalled,
    /// On, and an error when the layer is missing.
    Required,
}

#[derive(Clone, Debug)]
pub struct GpuOptions {
    pub validation: Validation,
    /// Index into [`list_devices`]; `None` picks the best device.
    pub device_index: Option<usize>,
}

impl Default for GpuOptions {
    fn default() -> Self {
        Self {
            validation: Validation::Off,
            device_index: None,
        }
    }
}

/// What `isr devices` prints about one physical device.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub kind: vk::PhysicalDeviceType,
    pub driver: String,
    pub api_version: (u32, u32, u32),
    /// Why the device cannot run `isr`, if it cannot.
    pub unusable: Option<String>,
}

impl DeviceInfo {
    pub fn kind_name(&self) -> &'static str {
        match self.kind {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual",
            vk::PhysicalDeviceType::CPU => "cpu",
            _ => "other",
        }
    }
}

/// Optional device features `isr` uses when present and reports as missing otherwise.
#[derive(Clone, Copy, Debug, Default)]
pub struct OptionalFeatures {
    pub pipeline_statistics: bool,
    pub precise_occlusion: bool,
    /// `timestampValidBits > 0` on the queue and `timestampComputeAndGraphics`.
    pub timestamps: bool,
    /// `gl_Layer` written by vertex shaders (layered multiresolution passes).
    pub shader_output_layer: bool,
    /// Atomics in fragment shaders (patch counts).
    pub fragment_atomics: bool,
}

/// Messages the validation layer reported, collected so that tests can fail on them.
#[derive(Default)]
pub struct ValidationLog {
    messages: Mutex<Vec<String>>,
}

impl ValidationLog {
    pub fn take(&self) -> Vec<String> {
        std::mem::take(&mut *self.messages.lock().unwrap())
    }
}

/// What every Vulkan object's owner needs to free it: the device, the
/// allocator, and (destroyed last, in `Drop`) the messenger and the instance.
/// Resources hold an `Arc` of it, so the device outlives every object made
/// from it, whatever order values are dropped in.
pub struct Shared {
    pub device: ash::Device,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    instance: ash::Instance,
    debug_utils: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Kept alive until the messenger that writes to it is gone.
    _validation_log: Option<Arc<ValidationLog>>,
    /// The loaded Vulkan library, unloaded only after everything above is
    /// destroyed (fields drop after `drop`).
    _entry: ash::Entry,
}

impl Drop for Shared {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            // The validation layer reports objects still alive here.
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug_utils.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

pub struct Gpu {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    /// The same device as `shared.device`, for recording commands.
    pub device: ash::Device,
    pub physical: vk::PhysicalDevice,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub properties: vk::PhysicalDeviceProperties,
    pub info: DeviceInfo,
    pub features: OptionalFeatures,
    pub shared: Arc<Shared>,
    pub command_pool: vk::CommandPool,
    /// Signalled by each `submit_and_wait`; reused rather than made per submission.
    submit_fence: vk::Fence,
    /// Object names and command labels, present when VK_EXT_debug_utils is.
    pub debug_device: Option<ash::ext::debug_utils::Device>,
    validation_log: Option<Arc<ValidationLog>>,
    /// The test hook of `fault.rs`; `None` in normal runs.
    injected_fault: Option<fault::InjectedFault>,
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let message = if data.is_null() || (*data).p_message.is_null() {
        String::from("(no message)")
    } else {
        CStr::from_ptr((*data).p_message)
            .to_string_lossy()
            .into_owned()
    };
    let level = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        "error"
    } else {
        "warning"
    };
    eprintln!("validation {level}: {message}");
    if let Some(log) = (user as *const ValidationLog).as_ref() {
        log.messages
            .lock()
            .unwrap()
            .push(format!("{level}: {message}"));
    }
    vk::FALSE
}

fn load_entry() -> Result<ash::Entry> {
    // SAFETY: loading the system Vulkan loader; no Vulkan calls are in flight.
    unsafe { ash::Entry::load() }.map_err(|e| {
        anyhow!("could not load the Vulkan loader (libvulkan.so.1): {e}; {INSTALL_DRIVER_HINT}")
    })
}

fn layer_installed(entry: &ash::Entry) -> bool {
    unsafe { entry.enumerate_instance_layer_properties() }
        .unwrap_or_default()
        .iter()
        .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER))
}

fn create_instance(entry: &ash::Entry, validate: bool) -> Result<ash::Instance> {
    create_instance_with(entry, validate, &[])
}

/// An instance with the `required` extensions besides the debug ones.
fn create_instance_with(
    entry: &ash::Entry,
    validate: bool,
    required: &[*const std::ffi::c_char],
) -> Result<ash::Instance> {
    let app = vk::ApplicationInfo::default()
        .application_name(c"isr")
        .api_version(vk::API_VERSION_1_3);
    let available: Vec<String> = unsafe { entry.enumerate_instance_extension_properties(None) }
        .unwrap_or_default()
        .iter()
        .filter_map(|e| e.extension_name_as_c_str().ok())
        .map(|s| s.to_string_lossy().into_owned())
        .collect();
    let mut extensions = required.to_vec();
    if validate || available.iter().any(|e| e == "VK_EXT_debug_utils") {
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    let mut layers = Vec::new();
    let sync_validation = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features =
        vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync_validation);
    let mut info = vk::InstanceCreateInfo::default().application_info(&app);
    if validate {
        layers.push(VALIDATION_LAYER.as_ptr());
        // The layer itself provides VK_EXT_validation_features.
        extensions.push(ash::ext::validation_features::NAME.as_ptr());
        info = info.push_next(&mut features);
    }
    let info = info
        .enabled_extension_names(&extensions)
        .enabled_layer_names(&layers);
    match unsafe { entry.create_instance(&info, None) } {
        Ok(i) => Ok(i),
        Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => {
            bail!("no Vulkan 1.3 driver found (vkCreateInstance: ERROR_INCOMPATIBLE_DRIVER); {INSTALL_DRIVER_HINT}")
        }
        Err(e) => bail!("vkCreateInstance failed: {e}; {INSTALL_DRIVER_HINT}"),
    }
}

impl Gpu {
    pub fn new(options: &GpuOptions) -> Result<Self> {
        Self::with_extensions(options, &[], &[])
    }

    /// As `new`, with extra instance and device extensions (the viewer's
    /// surface and swapchain; headless runs need none).
    pub fn with_extensions(
        options: &GpuOptions,
        instance_extensions: &[*const std::ffi::c_char],
        device_extensions: &[*const std::ffi::c_char],
    ) -> Result<Self> {
        let injected_fault = fault::InjectedFault::from_env()?;
        let entry = load_entry()?;
        let validate = match options.validation {
            Validation::Off => false,
            Validation::IfInstalled => layer_installed(&entry),
            Validation::Required => {
                if !layer_installed(&entry) {
                    bail!(
                        "--validate needs the Khronos validation layer, which is not installed; \
                         on Debian or Ubuntu: `sudo apt-get install vulkan-validationlayers`"
                    );
                }
                true
            }
        };
        let instance = create_instance_with(&entry, validate, instance_extensions)?;
        // From here on, failures must destroy the messenger and the instance (in
        // that order, before the log the messenger writes to); a guard does it.
        let mut guard = InstanceGuard {
            instance: Some(instance.clone()),
            debug_utils: None,
            validation_log: None,
        };
        if validate {
            let log = Arc::new(ValidationLog::default());
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE
                        | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&log) as *mut c_void);
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .context("creating the validation debug messenger")?;
            guard.debug_utils = Some((loader, messenger));
            guard.validation_log = Some(log);
        }

        let physical_devices = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
        if physical_devices.is_empty() {
            bail!("no Vulkan device found; {INSTALL_DRIVER_HINT}");
        }
        let infos: Vec<DeviceInfo> = physical_devices
            .iter()
            .enumerate()
            .map(|(i, &pd)| describe(&instance, i, pd))
            .collect();
        let info = match options.device_index {
            Some(i) => {
                let Some(info) = infos.get(i) else {
                    bail!(
                        "--device {i}: there are only {} Vulkan devices (indices 0..{}); `isr devices` lists them",
                        infos.len(),
                        infos.len() - 1
                    );
                };
                if let Some(why) = &info.unusable {
                    bail!("--device {i} ({}) cannot run isr: it {why}", info.name);
                }
                info.clone()
            }
            None => infos
                .iter()
                .filter(|d| d.unusable.is_none())
                .min_by_key(|d| (type_rank(d.kind), d.index))
                .cloned()
                .ok_or_else(|| {
                    let list: Vec<String> = infos
                        .iter()
                        .map(|d| format!("{} ({})", d.name, d.unusable.clone().unwrap_or_default()))
                        .collect();
                    anyhow!(
                        "no Vulkan device can run isr: {}; {INSTALL_DRIVER_HINT}",
                        list.join(", ")
                    )
                })?,
        };
        let physical = physical_devices[info.index];
        let properties = unsafe { instance.get_physical_device_properties(physical) };
        let queue_family = graphics_queue_family(&instance, physical).unwrap();
        let family_props =
            unsafe { instance.get_physical_device_queue_family_properties(physical) }
                [queue_family as usize];

        let mut supported12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut supported2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut supported12);
        unsafe { instance.get_physical_device_features2(physical, &mut supported2) };
        let supported = supported2.features;
        let features = OptionalFeatures {
            pipeline_statistics: supported.pipeline_statistics_query == vk::TRUE,
            precise_occlusion: supported.occlusion_query_precise == vk::TRUE,
            timestamps: family_props.timestamp_valid_bits > 0
                && properties.limits.timestamp_compute_and_graphics == vk::TRUE,
            shader_output_layer: supported12.shader_output_layer == vk::TRUE,
            fragment_atomics: supported.fragment_stores_and_atomics == vk::TRUE,
        };
        let enabled = vk::PhysicalDeviceFeatures::default()
            .pipeline_statistics_query(features.pipeline_statistics)
            .occlusion_query_precise(features.precise_occlusion)
            .fragment_stores_and_atomics(features.fragment_atomics);
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .shader_output_layer(features.shader_output_layer);
        // Demote is required by Vulkan 1.3; glslang compiles `discard` to it for SPIR-V 1.6.
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true)
            .shader_demote_to_helper_invocation(true);
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(device_extensions)
            .enabled_features(&enabled)
            .push_next(&mut f13)
            .push_next(&mut f12);
        let device = unsafe { instance.create_device(physical, &device_info, None) }
            .with_context(|| format!("creating a Vulkan device on {}", info.name))?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };

        let allocator = match Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        }) {
            Ok(a) => a,
            Err(e) => {
                unsafe { device.destroy_device(None) };
                return Err(anyhow::Error::from(e).context("creating the GPU memory allocator"));
            }
        };

        // From here on `Shared` owns the device, allocator, messenger and
        // instance, and frees them when its last holder is gone.
        guard.instance = None;
        let debug_utils = guard.debug_utils.take();
        let validation_log = guard.validation_log.take();
        let debug_device = debug_utils
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device));
        let shared = Arc::new(Shared {
            device: device.clone(),
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            instance: instance.clone(),
            debug_utils,
            _validation_log: validation_log.clone(),
            _entry: entry.clone(),
        });
        let command_pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
        }?;
        let submit_fence =
            match unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) } {
                Ok(f) => f,
                Err(e) => {
                    unsafe { device.destroy_command_pool(command_pool, None) };
                    return Err(e.into());
                }
            };
        Ok(Self {
            entry,
            instance,
            device,
            physical,
            queue,
            queue_family,
            properties,
            info,
            features,
            shared,
            command_pool,
            submit_fence,
            debug_device,
            validation_log,
            injected_fault,
        })
    }

    /// True when the validation layer is loaded.
    pub fn validating(&self) -> bool {
        self.validation_log.is_some()
    }

    /// The validation log itself, to read what the layer reports while the
    /// device is destroyed (undestroyed objects), after the `Gpu` is gone.
    pub fn validation_log(&self) -> Option<Arc<ValidationLog>> {
        self.validation_log.clone()
    }

    /// Validation messages reported since the last call.
    pub fn take_validation_messages(&self) -> Vec<String> {
        self.validation_log
            .as_ref()
            .map(|l| l.take())
            .unwrap_or_default()
    }

    /// An error when the validation layer reported anything since the last
    /// take (the messages were printed as they came).
    pub fn validation_verdict(&self) -> Result<()> {
        let messages = self.take_validation_messages();
        if !messages.is_empty() {
            bail!(
                "the validation layer reported {} message(s) (printed above)",
                messages.len()
            );
        }
        Ok(())
    }

    /// The first of `candidates` whose optimal tiling supports `features`.
    pub fn pick_format(
        &self,
        candidates: &[vk::Format],
        features: vk::FormatFeatureFlags,
    ) -> Option<vk::Format> {
        candidates.iter().copied().find(|&f| {
            let p = unsafe {
                self.instance
                    .get_physical_device_format_properties(self.physical, f)
            };
            p.optimal_tiling_features.contains(features)
        })
    }

    pub fn limits(&self) -> &vk::PhysicalDeviceLimits {
        &self.properties.limits
    }

    /// Names a Vulkan object for validation messages and capture tools.
    pub fn name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(d) = &self.debug_device {
            let Ok(cname) = std::ffi::CString::new(name) else {
                return;
            };
            let info = vk::DebugUtilsObjectNameInfoEXT::default()
                .object_handle(handle)
                .object_name(&cname);
            unsafe {
                let _ = d.set_debug_utils_object_name(&info);
            }
        }
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_fence(self.submit_fence, None);
            self.device.destroy_command_pool(self.command_pool, None);
        }
        // `shared` goes with the last resource that holds it.
    }
}

/// Destroys the messenger and the instance if device creation fails half-way;
/// the log is dropped after them (fields drop after `drop`).
struct InstanceGuard {
    instance: Option<ash::Instance>,
    debug_utils: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    validation_log: Option<Arc<ValidationLog>>,
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        let Some(instance) = self.instance.take() else {
            return;
        };
        unsafe {
            if let Some((loader, messenger)) = self.debug_utils.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            instance.destroy_instance(None);
        }
    }
}
