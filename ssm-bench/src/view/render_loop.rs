//! The viewer's render loop: on each redraw, the selected technique rendered when something
//! changed, its error against the cached ground truth, its counted work (once per technique and
//! setting), the image shown, then the panel.

use std::io::Write;

use anyhow::Result;
use ssm_core::metrics::{self, ErrorMetrics};
use ssm_core::reference::surface_points;
use ssm_core::{ParamValues, TechniqueKind};

use super::ui::Actions;
use super::{CountedWork, FrameReport, Live, ViewMode, WorkOutcome};
use crate::data::work::{GROUND_TRUTH_NOT_COUNTED, Totals};
use crate::present::work::cell;
use crate::stats::average;

impl Live {
    /// Reads the G-buffer's points for the current view and looks the
    /// ground truth of each light up in the cache (the reference technique's
    /// current samples and seed; centre sampling unless it asks otherwise).
    pub(super) fn look_up_truth(&mut self) -> Result<()> {
        let positions = self.renderer.read_positions()?;
        let normals = self.renderer.read_normals()?;
        self.truth.covered = positions.iter().map(|p| p[3] > 0.5).collect();
        // The reference technique's parameters, or its defaults when it is not among those shown.
        let defaults = ParamValues::defaults(ssm_core::reference::NAME, ssm_core::reference::PARAMS);
        let reference = self.slots.iter().find(|s| s.info.kind == TechniqueKind::GroundTruth).map_or(&defaults, |s| &s.params);
        // The parameters' declared ranges make the conversions exact.
        let sampling = ssm_core::reference::Sampling {
            samples_per_axis: u32::try_from(reference.int("samples")?)?,
            refine: u32::try_from(reference.int("refine")?)?,
        };
        let seed = u64::try_from(reference.int("seed")?)?;
        let footprint = reference.choice("footprint")? == "pixel";
        let points = surface_points(&positions, &normals, &self.renderer.scene.camera, footprint);
        self.truth.images = self
            .renderer
            .scene
            .light_frames
            .iter()
            .map(|frame| self.truth.cache.cached(&frame.light, &points, sampling, seed, &self.truth.cache_dir))
            .collect();
        Ok(())
    }

    /// Renders the selected technique when something changed, then draws the panel and presents.
    pub(super) fn redraw(&mut self) -> Result<()> {
        if self.camera_moved {
            self.camera_moved = false;
            self.renderer.set_camera(&self.orbit.camera)?;
            // The ground truth keeps the points it traced: it must see the new view.
            for slot in self.slots.iter_mut().filter(|s| s.info.kind == TechniqueKind::GroundTruth) {
                slot.instance = None;
            }
            self.look_up_truth()?;
            self.dirty = true;
        }
        let mut encoder = self.renderer.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view_encoder") });
        if self.dirty || self.continuous {
            self.dirty = false;
            self.render_technique(&mut encoder);
        }

        let raw_input = self.egui_state.take_egui_input(&self.window);
        let mut actions = Actions::default();
        let mut full_output = {
            let ctx = self.egui_ctx.clone();
            ctx.run_ui(raw_input, |ui| self.panel(ui, &mut actions))
        };
        self.egui_state.handle_platform_output(&self.window, std::mem::take(&mut full_output.platform_output));
        self.apply(actions);
        // egui's font atlas and images: uploaded before anything can return early, freed at the end.
        let gpu = self.renderer.gpu.clone();
        for (id, deltas) in full_output.textures_delta.set.drain() {
            for delta in &deltas {
                self.egui_renderer.update_texture(&gpu.device, &gpu.queue, id, delta);
            }
        }
        let freed: Vec<egui::TextureId> = full_output.textures_delta.free.drain().collect();
        let result = self.paint(encoder, full_output);
        for id in &freed {
            self.egui_renderer.free_texture(id);
        }
        result
    }

    /// Renders one frame of the selected technique, measures it, and copies its shaded image to the display texture.
    fn render_technique(&mut self, encoder: &mut wgpu::CommandEncoder) {
        self.report = FrameReport::default();
        let slot = &mut self.slots[self.current];
        if slot.instance.is_none() {
            match self.renderer.create_technique(slot.info, &slot.params) {
                Ok(instance) => slot.instance = Some(instance),
                Err(error) => {
                    self.report.failure = Some(format!("{error}"));
                    return;
                }
            }
        }
        let Some(instance) = slot.instance.as_deref_mut() else { return };
        let timings = match self.renderer.render(instance, slot.info.name) {
            Ok(timings) => timings,
            Err(error) => {
                self.report.failure = Some(format!("{error}"));
                // A failed frame may have left the instance half-way: make it afresh next time.
                slot.instance = None;
                return;
            }
        };
        let name = slot.info.name;
        let params = slot.params.to_string();
        let traced_truth = slot.info.kind == TechniqueKind::GroundTruth;
        self.report.timings = Some(timings);
        self.count_work_once();
        // The ground truth just traced this view into the cache: the other techniques' error can now be shown.
        if traced_truth && let Err(error) = self.look_up_truth() {
            self.report.failure = Some(format!("{error}"));
        }
        let lights = self.renderer.scene.light_count();
        // Read back only what is shown or measured: the shaded view without a cached truth needs nothing.
        let read = self.mode != ViewMode::Shaded || self.truth.images.iter().all(Option::is_some);
        let visibility = match (0..if read { lights } else { 0 })
            .map(|light| self.renderer.read_visibility(light, name))
            .collect::<ssm_core::Result<Vec<_>>>()
        {
            Ok(visibility) => visibility,
            Err(error) => {
                self.report.failure = Some(format!("{error}"));
                return;
            }
        };
        self.measure_error(&visibility);
        self.light = self.light.min(lights.saturating_sub(1));
        let shown = self.show(encoder, &visibility);
        self.frame += 1;
        self.announce = Some(format!("ssm view: showing {name} [{params}] frame {} view {}", self.frame, shown.name()));
    }

    /// With "count work" on, counts the selected technique's work in one extra, untimed frame,
    /// unless it was counted at these settings already, and announces it on stdout.
    fn count_work_once(&mut self) {
        let slot = &self.slots[self.current];
        let params = slot.params.to_string();
        let counted = self.work.as_ref().is_some_and(|w| w.slot == self.current && w.params == params);
        if !self.count_work || counted {
            return;
        }
        let outcome = match crate::measure::work::count(&mut self.renderer, slot.info, &slot.params) {
            Ok(Some(work)) => WorkOutcome::Counted(work),
            Ok(None) => WorkOutcome::NotCounted(GROUND_TRUTH_NOT_COUNTED),
            Err(error) => WorkOutcome::Failed(format!("{error}")),
        };
        let summary = match &outcome {
            WorkOutcome::Counted(work) => {
                let totals = Totals::of(work);
                format!("passes {} invocations {} texel_reads {}", work.passes.len(), cell(totals.invocations()), cell(totals.texel_reads))
            }
            WorkOutcome::NotCounted(why) => (*why).to_owned(),
            WorkOutcome::Failed(error) => format!("failed: {error}"),
        };
        let mut stdout = std::io::stdout();
        // A closed stdout (the caller stopped reading) must not stop the viewer.
        let _ = writeln!(stdout, "ssm view: counted {} [{params}] {summary}", slot.info.name);
        let _ = stdout.flush();
        self.work = Some(CountedWork { slot: self.current, params, outcome });
    }

    /// Puts the frame just rendered into the display texture as the chosen view; returns the
    /// view shown (the signed error falls back to the visibility without a cached ground truth).
    fn show(&mut self, encoder: &mut wgpu::CommandEncoder, visibility: &[Vec<f32>]) -> ViewMode {
        let (width, height) = (self.renderer.width(), self.renderer.height());
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let image = visibility.get(self.light).map_or(&[][..], Vec::as_slice);
        let truth = self.truth.images.get(self.light).and_then(Option::as_ref).map(|truth| truth.visibility.as_slice());
        let (mode, rgba): (ViewMode, Vec<u8>) = match (self.mode, truth) {
            (ViewMode::Shaded, _) => {
                match self.renderer.shade_on_gpu() {
                    Ok(shaded) => encoder.copy_texture_to_texture(shaded.as_image_copy(), self.display.as_image_copy(), size),
                    Err(error) => self.report.failure = Some(format!("{error}")),
                }
                return ViewMode::Shaded;
            }
            // The static report's heat map: red where darker than the truth, blue where lighter, full at 0.5.
            (ViewMode::SignedError, Some(truth)) => (
                ViewMode::SignedError,
                metrics::heat_map(truth, image, &self.truth.covered, 0.5).chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
            ),
            _ => (
                ViewMode::Visibility,
                image.iter().map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8).flat_map(|v| [v, v, v, 255]).collect(),
            ),
        };
        if rgba.len() == (width * height * 4) as usize {
            self.renderer.gpu.queue.write_texture(
                self.display.as_image_copy(),
                &rgba,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * width), rows_per_image: Some(height) },
                size,
            );
        }
        mode
    }

    /// The error of the frame just rendered against the cached ground truth, averaged over the lights.
    fn measure_error(&mut self, visibility: &[Vec<f32>]) {
        let (width, height) = (self.renderer.width() as usize, self.renderer.height() as usize);
        if self.truth.images.iter().any(Option::is_none) {
            let key = self.slots.iter().position(|s| s.info.kind == TechniqueKind::GroundTruth).map(|i| i + 1);
            self.report.note = Some(match key {
                Some(key) => format!("no ground truth cached for this view: key {key} traces it"),
                None => "no ground truth cached for this view".into(),
            });
            return;
        }
        let per_light: Vec<ErrorMetrics> = self
            .truth
            .images
            .iter()
            .zip(visibility)
            .filter_map(|(truth, image)| {
                truth.as_ref().map(|truth| {
                    metrics::compare_with_noise(&truth.visibility, Some(&truth.noise), image, &self.truth.covered, width, height)
                })
            })
            .collect();
        if !per_light.is_empty() {
            self.report.error = Some(average(&per_light));
        }
    }
}
