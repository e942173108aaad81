//! What the interactive viewer needs beyond `render_frames`: one frame at a
//! time with the caller's commands and semaphores appended
//! ([`FrameExtension`]), waits on the frames in flight, and a method switch
//! that remakes only the method's resources.

use super::*;

/// What a caller adds to each frame of `Renderer::render_frame`: commands
/// recorded after `tonemap` into the frame's last command buffer (passes
/// timed with the frame's profiler), and the semaphores its submission waits
/// on and signals (a swapchain image's acquisition and presentation).
pub trait FrameExtension {
    fn record(&mut self, ctx: &FrameContext, profiler: &mut Profiler) -> Result<()>;
    /// A semaphore to wait on before the given stages.
    fn wait(&self) -> Option<(vk::Semaphore, vk::PipelineStageFlags2)>;
    fn signal(&self) -> Option<vk::Semaphore>;
}

impl<'g> Renderer<'g> {
    /// Waits for the frame the next `render_frame` will replace, and returns
    /// its per-pass numbers (`None` when its slot held no frame). After this
    /// the semaphores that frame waited on may be reused.
    pub fn wait_next_slot(&mut self) -> Result<Option<Vec<PassSample>>> {
        let mut stats = FrameStats::default();
        self.complete(self.next_slot, &mut stats)?;
        Ok(stats.frames.pop())
    }

    /// Renders one frame of the current frame state, followed by what
    /// `extension` records (the viewer's presentation: the same frame as
    /// `render_frames`, plus a copy into a window). Does not wait for it;
    /// returns the numbers of the frame its slot held before, if any.
    pub fn render_frame(
        &mut self,
        extension: &mut dyn FrameExtension,
    ) -> Result<Option<Vec<PassSample>>> {
        let gpu = self.gpu;
        let finished = self.wait_next_slot()?;
        let slot = self.next_slot;
        self.next_slot = (slot + 1) % self.slots.len();
        let transforms = instance_transforms(&self.state);
        for v in 0..self.views.len() {
            let uniforms = self.view_uniforms(v);
            self.slots[slot].frames[v].write(&uniforms, &transforms);
        }
        // The viewer shows times only: no frame counts.
        self.record(slot, Some(&mut *extension), false)?;
        let submissions = self.submissions();
        let s = &mut self.slots[slot];
        let cmds = s.cmds[..submissions].to_vec();
        for &cmd in &cmds[..submissions - 1] {
            gpu.submit_and_wait(cmd)?;
        }
        unsafe { gpu.device.reset_fences(&[s.fence])? };
        gpu.submit_with_semaphores(
            cmds[submissions - 1],
            s.fence,
            extension.wait(),
            extension.signal(),
        )?;
        s.in_flight = Some((self.frames_submitted, Instant::now()));
        self.frames_submitted += 1;
        Ok(finished)
    }

    /// The slot (of `FRAMES_IN_FLIGHT`) the next `render_frame` uses.
    pub fn next_slot_index(&self) -> usize {
        self.next_slot
    }

    /// A frame set: the layout of set 0 for pipelines made outside the
    /// renderer (all frame sets share one definition).
    pub fn frame_set_layout(&self) -> &crate::vk::pipeline::DescriptorSet {
        &self.slots[0].frames[0].set
    }

    /// Waits until no frame is in flight (before reading results back or
    /// changing what frames use); returns the per-pass numbers of the frames
    /// that were.
    pub fn wait_idle(&mut self) -> Result<Vec<Vec<PassSample>>> {
        let mut stats = FrameStats::default();
        for slot in 0..self.slots.len() {
            self.complete(slot, &mut stats)?;
        }
        Ok(stats.frames)
    }

    /// Switches to `settings`, which may differ from the current ones only in
    /// the method and its parameters (VPLs, thresholds, tau, ...): what the
    /// targets and shared passes are made from (sizes, RSM resolution) must
    /// stay. Only the method's resources are made anew; the run uniforms are
    /// rewritten. On error the renderer keeps its current method.
    pub fn set_method_settings(&mut self, settings: &RenderSettings) -> Result<()> {
        let old = &self.settings;
        if (settings.width, settings.height, settings.rsm_resolution)
            != (old.width, old.height, old.rsm_resolution)
        {
            bail!("set_method_settings cannot change the output size or the RSM resolution");
        }
        let descriptor = check_run(
            self.gpu,
            settings,
            &self.state.lights,
            (self.views.len(), self.state.instance_transforms.len()),
            self.scene.plan.bytes(),
        )?;
        // The grid is made with the run (the frame sets bind it).
        let grid_in_use = reads_grid(descriptor, settings);
        let grid = crate::voxel_grid::GRID;
        if grid_in_use
            && (self.visibility_pass.is_none() || grid.get(settings) != grid.get(&self.settings))
        {
            bail!(
                "the voxel visibility grid is made when the run starts: to use --visibility \
                 voxels with --visibility-grid {}, start isr with them",
                grid.get(settings)
            );
        }
        // The frames in flight were of the old method; their numbers go.
        self.wait_idle()?;
        let gpu = self.gpu;
        let setup = Setup {
            gpu,
            frame: &self.slots[0].frames[0].set,
            targets: &self.targets,
            samplers: &self._samplers,
            scene: &self.scene,
            settings,
            grid_surface: self.voxel_grid.surface.as_ref(),
        };
        let method = crate::methods::create(&setup)?;
        let bounce = super::make_bounce(&setup, descriptor, self.views.len())?;
        let passes = (MAX_PASSES + method.submissions() as u32) * self.views.len() as u32;
        for slot in &mut self.slots {
            slot.profiler = Profiler::new(gpu, passes)?;
        }
        let values = run_uniforms(descriptor, settings);
        let bytes = bytemuck::bytes_of(&values).to_vec();
        let run = self.run_uniforms.0.buffer;
        gpu.run_once(|cmd| unsafe {
            // No frame is in flight (waited above); the update's writes
            // become visible to every later frame's reads.
            gpu.device.cmd_update_buffer(cmd, run, 0, &bytes);
            crate::vk::barrier::memory(
                gpu,
                cmd,
                vk::PipelineStageFlags2::ALL_TRANSFER,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                vk::AccessFlags2::MEMORY_READ,
            );
        })?;
        self.method = method;
        self.bounce = bounce;
        self.grid_in_use = grid_in_use;
        self.run_uniforms.1 = values;
        self.settings = settings.clone();
        Ok(())
    }
}
