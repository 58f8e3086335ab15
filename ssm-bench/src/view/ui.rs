//! The viewer's panel: the techniques (number keys), the view (S, V, E), a widget for each of the
//! selected technique's parameters, the last frame's times, error and counted work, and what the
//! user asked for ([`Actions`]) applied to the viewer's state.

use ssm_core::{ParamKind, ParamSpec, ParamValue, ParamValues, TechniqueKind};

use super::{Live, PANEL_WIDTH, ViewMode, WorkOutcome};
use crate::data::work::Totals;
use crate::present::work::{cell, notes};

impl Live {
    /// The panel and the image; what the user did is collected in `actions`.
    pub(super) fn panel(&mut self, ui: &mut egui::Ui, actions: &mut Actions) {
        let number_keys = [
            egui::Key::Num1,
            egui::Key::Num2,
            egui::Key::Num3,
            egui::Key::Num4,
            egui::Key::Num5,
            egui::Key::Num6,
            egui::Key::Num7,
            egui::Key::Num8,
            egui::Key::Num9,
            egui::Key::Num0,
        ];
        let typing = ui.ctx().egui_wants_keyboard_input();
        for (index, key) in number_keys.iter().enumerate().take(self.slots.len()) {
            if !typing && ui.input(|i| i.key_pressed(*key)) {
                actions.select = Some(index);
            }
        }
        for (key, mode) in [(egui::Key::S, ViewMode::Shaded), (egui::Key::V, ViewMode::Visibility), (egui::Key::E, ViewMode::SignedError)] {
            if !typing && ui.input(|i| i.key_pressed(key)) {
                actions.mode = Some(mode);
            }
        }
        if !typing && ui.input(|i| i.key_pressed(egui::Key::W)) {
            actions.count_work = Some(!self.count_work);
        }
        egui::Panel::right("view_panel").exact_size(PANEL_WIDTH).resizable(false).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading(format!("ssm view: {}", self.scene_name));
                ui.label(format!("{}×{} px on {}", self.renderer.width(), self.renderer.height(), self.renderer.gpu.describe()));
                ui.separator();
                ui.strong("technique (number keys)");
                for (index, slot) in self.slots.iter().enumerate() {
                    let label = format!("{}  {}", (index + 1) % 10, slot.info.name);
                    if ui.selectable_label(index == self.current, label).on_hover_text(slot.info.summary).clicked() {
                        actions.select = Some(index);
                    }
                }
                ui.separator();
                ui.strong("view (S, V, E)");
                ui.horizontal(|ui| {
                    for (mode, label) in
                        [(ViewMode::Shaded, "shaded"), (ViewMode::Visibility, "visibility"), (ViewMode::SignedError, "signed error")]
                    {
                        if ui.selectable_label(self.mode == mode, label).clicked() {
                            actions.mode = Some(mode);
                        }
                    }
                });
                let lights = self.renderer.scene.light_count();
                if lights > 1 && self.mode != ViewMode::Shaded {
                    let mut light = self.light;
                    ui.add(egui::Slider::new(&mut light, 0..=lights - 1).text("light"));
                    if light != self.light {
                        actions.light = Some(light);
                    }
                }
                if self.mode == ViewMode::SignedError {
                    ui.label(if self.truth.images.get(self.light).is_some_and(Option::is_some) {
                        "red: darker than the ground truth, blue: lighter; full colour at ±0.5"
                    } else {
                        "no cached ground truth for this view: showing the visibility"
                    });
                }
                ui.separator();
                let slot = &self.slots[self.current];
                ui.strong(format!("{} parameters", slot.info.name));
                for spec in slot.info.params {
                    if let Some(value) = parameter_widget(ui, spec, &slot.params) {
                        actions.set = Some((spec.name, value));
                    }
                }
                if !slot.info.params.is_empty() && ui.button("defaults").clicked() {
                    actions.defaults = true;
                }
                ui.checkbox(&mut self.continuous, "render continuously");
                let mut count_work = self.count_work;
                ui.checkbox(&mut count_work, "count work per pass (W)").on_hover_text(
                    "one extra, untimed frame per technique and setting: invocations, texel reads, bytes stored (shown under the times)",
                );
                if count_work != self.count_work {
                    actions.count_work = Some(count_work);
                }
            });
        });
        egui::CentralPanel::default().show(ui, |ui| {
            let pixels_per_point = ui.ctx().pixels_per_point();
            let size = egui::vec2(self.renderer.width() as f32, self.renderer.height() as f32) / pixels_per_point;
            let image = egui::Image::new(egui::load::SizedTexture::new(self.display_id, size)).sense(egui::Sense::click_and_drag());
            let response = ui.add(image);
            let rect = response.rect;
            self.image_origin = [rect.min.x * pixels_per_point, rect.min.y * pixels_per_point].map(|v| v.round() as i64);
            let drag = response.drag_delta();
            if drag != egui::Vec2::ZERO {
                actions.orbit = Some((-drag.x * 0.01, -drag.y * 0.01));
            }
            if response.hovered() {
                let scroll = ui.input(|i| i.smooth_scroll_delta.y);
                if scroll != 0.0 {
                    actions.dolly = Some((-scroll * 0.002).exp());
                }
            }
            ui.label("drag: orbit · wheel: closer / further");
            ui.separator();
            egui::ScrollArea::vertical().show(ui, |ui| self.report_ui(ui));
        });
    }

    fn report_ui(&self, ui: &mut egui::Ui) {
        if let Some(failure) = &self.report.failure {
            ui.colored_label(egui::Color32::from_rgb(230, 80, 80), failure);
        }
        self.error_ui(ui);
        ui.add_space(8.0);
        self.timings_ui(ui);
        if self.count_work {
            ui.add_space(8.0);
            self.work_ui(ui);
        }
    }

    /// The selected technique's counted work per pass: invocations (vertex, fragment, compute),
    /// texel reads and bytes stored to targets; `-` where not counted.
    fn work_ui(&self, ui: &mut egui::Ui) {
        let params = self.slots[self.current].params.to_string();
        let Some(work) = self.work.as_ref().filter(|w| w.slot == self.current && w.params == params) else {
            ui.label("counted work: at the next frame");
            return;
        };
        match &work.outcome {
            WorkOutcome::NotCounted(why) => {
                ui.label(format!("counted work: {why}"));
            }
            WorkOutcome::Failed(error) => {
                ui.colored_label(egui::Color32::from_rgb(230, 80, 80), format!("counting the work failed: {error}"));
            }
            WorkOutcome::Counted(frame) => {
                ui.strong("counted work per pass (one untimed frame, every light)");
                egui::Grid::new("view_work").striped(true).show(ui, |ui| {
                    for heading in ["pass", "vertex", "fragment", "compute", "texel reads", "target bytes"] {
                        ui.label(heading);
                    }
                    ui.end_row();
                    let totals = Totals::of(frame);
                    let rows = frame.passes.iter().map(|p| (p.name.as_str(), Totals::of_passes(frame, std::slice::from_ref(p))));
                    for (name, counts) in rows.chain([("frame", totals)]) {
                        ui.label(name);
                        ui.label(cell(counts.vertex_invocations));
                        ui.label(cell(counts.fragment_invocations));
                        ui.label(cell(counts.compute_invocations));
                        ui.label(cell(counts.texel_reads));
                        ui.label(counts.target_bytes.to_string());
                        ui.end_row();
                    }
                });
                for note in notes(&[(self.slots[self.current].info.name, frame)]) {
                    ui.label(note.replace('`', ""));
                }
            }
        }
    }

    fn timings_ui(&self, ui: &mut egui::Ui) {
        if let Some(timings) = &self.report.timings {
            match timings.gpu_ms {
                Some(ms) => ui.strong(format!("frame {:.2} ms GPU ({:.1} ms wall)", ms, timings.cpu_wall_ms)),
                None => ui.strong(format!("frame {:.1} ms wall (no GPU timestamps)", timings.cpu_wall_ms)),
            };
            egui::Grid::new("view_passes").striped(true).show(ui, |ui| {
                for pass in &timings.passes {
                    ui.label(&pass.name);
                    ui.label(format!("light {}", pass.light));
                    ui.label(format!("{:.3} ms", pass.ms));
                    ui.end_row();
                }
            });
        }
    }

    fn error_ui(&self, ui: &mut egui::Ui) {
        match (&self.report.error, &self.report.note) {
            (Some(error), _) => {
                ui.strong("error against the cached ground truth");
                egui::Grid::new("view_error").striped(true).show(ui, |ui| {
                    for (name, value) in [
                        ("MAE (shadowed in either)", error.mae),
                        ("± the truth's own", error.truth_noise.unwrap_or(f64::NAN)),
                        ("MAE umbra+penumbra", error.mae_penumbra),
                        ("RMSE", error.rmse),
                        ("SSIM", error.ssim),
                        ("umbra leak", error.umbra_leak),
                        ("pixels > 0.05", error.frac_over_0_05),
                    ] {
                        ui.label(name);
                        ui.label(format!("{value:.4}"));
                        ui.end_row();
                    }
                });
            }
            (None, Some(note)) => {
                ui.label(note);
            }
            (None, None) => {}
        }
    }

    pub(super) fn apply(&mut self, actions: Actions) {
        if let Some(index) = actions.select
            && index != self.current
        {
            self.current = index;
            self.dirty = true;
        }
        if let Some(mode) = actions.mode
            && mode != self.mode
        {
            self.mode = mode;
            self.dirty = true;
        }
        if let Some(light) = actions.light {
            self.light = light;
            self.dirty = true;
        }
        if let Some(count_work) = actions.count_work {
            self.count_work = count_work;
            // A frame to count at (once; later frames of the same setting count nothing).
            self.dirty |= count_work;
        }
        let slot = &mut self.slots[self.current];
        let mut params_changed = false;
        if let Some((name, text)) = actions.set {
            match slot.params.set(name, &text) {
                Ok(()) => params_changed = true,
                Err(error) => self.report.failure = Some(format!("{error}")),
            }
        }
        if actions.defaults {
            slot.params = slot.info.default_params();
            params_changed = true;
        }
        if params_changed {
            slot.instance = None;
            self.dirty = true;
            // The ground truth's samples, seed and footprint are part of its cache key.
            if slot.info.kind == TechniqueKind::GroundTruth
                && let Err(error) = self.look_up_truth()
            {
                self.report.failure = Some(format!("{error}"));
            }
        }
        if let Some((yaw, pitch)) = actions.orbit {
            self.orbit.rotate(yaw, pitch);
            self.camera_moved = true;
        }
        if let Some(factor) = actions.dolly {
            self.orbit.dolly(factor);
            self.camera_moved = true;
        }
        if self.dirty || self.camera_moved {
            self.window.request_redraw();
        }
    }
}

/// What the user asked for during one pass of the panel.
#[derive(Default)]
pub(super) struct Actions {
    select: Option<usize>,
    /// A parameter's new value, as text for [`ParamValues::set`].
    set: Option<(&'static str, String)>,
    defaults: bool,
    mode: Option<ViewMode>,
    light: Option<usize>,
    /// "count work" switched on or off.
    count_work: Option<bool>,
    orbit: Option<(f32, f32)>,
    dolly: Option<f32>,
}

/// A widget for one parameter, built from its declared kind; the new value
/// as text when the user changed it.
fn parameter_widget(ui: &mut egui::Ui, spec: &ParamSpec, params: &ParamValues) -> Option<String> {
    let current = params.iter().find(|(name, _)| *name == spec.name).map(|(_, value)| value)?;
    let response = ui.horizontal(|ui| {
        match (spec.kind, current) {
            (ParamKind::Bool { .. }, ParamValue::Bool(mut value)) => {
                ui.checkbox(&mut value, spec.name).changed().then(|| value.to_string())
            }
            (ParamKind::Int { min, max, .. }, ParamValue::Int(mut value)) => {
                // A slider over a range of billions (a seed) is useless: drag the number instead.
                let widget: egui::Response = if max - min <= 100_000 {
                    ui.add(egui::Slider::new(&mut value, min..=max).logarithmic(min > 0 && max / min.max(1) >= 64).text(spec.name))
                } else {
                    ui.add(egui::DragValue::new(&mut value).range(min..=max)) | ui.label(spec.name)
                };
                widget.changed().then(|| value.to_string())
            }
            (ParamKind::Float { min, max, .. }, ParamValue::Float(mut value)) => {
                let logarithmic = min > 0.0 && max / min >= 100.0;
                ui.add(egui::Slider::new(&mut value, min..=max).logarithmic(logarithmic).text(spec.name))
                    .changed()
                    .then(|| format!("{value}"))
            }
            (ParamKind::Choice { options, .. }, ParamValue::Choice(value)) => {
                let mut chosen = value;
                egui::ComboBox::from_label(spec.name).selected_text(value).show_ui(ui, |ui| {
                    for option in options {
                        ui.selectable_value(&mut chosen, *option, *option);
                    }
                });
                (chosen != value).then(|| chosen.to_string())
            }
            _ => None,
        }
    });
    response.response.on_hover_text(spec.doc);
    response.inner
}
