//! The egui side panel: every model parameter live (Sladović 2014 §4), the environment, the
//! look (Maslova §1.4: colour, diffuse and specular coefficients 0–1; light), live
//! statistics with a plot, and a button for bevy-inspector-egui's world inspector.
//! Every widget has a range and clamps what is typed into it.

use bevy::prelude::*;
use bevy_cloth::StatSample;
use bevy_cloth::params::{
    Air, Environment, GoalUpdate, Integrator, Model, ModelKind, PatchTargets, RotationMethod,
    ShapeMatchingParams, SpringFamily, SpringParams, Substeps, WindField, XpbdSolve,
};
use bevy_cloth::prelude::*;
use bevy_egui::{EguiContexts, EguiPrimaryContextPass, egui};
use bevy_inspector_egui::quick::WorldInspectorPlugin;

/// Colour and Maslova's reflection coefficients of a cloth.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct ClothLook {
    /// Base colour, linear RGB.
    pub color: [f32; 3],
    /// Colours of a garment's pieces (Maslova Fig. 4.2–4.3: front and back may differ),
    /// drawn as vertex colours; empty for one colour.
    pub piece_colors: Vec<[f32; 3]>,
    /// Diffuse coefficient k_d, 0–1.
    pub diffuse: f32,
    /// Specular coefficient k_s, 0–1.
    pub specular: f32,
}

impl ClothLook {
    /// A look of this colour with matte cotton's coefficients.
    pub fn from_color(color: [f32; 3]) -> Self {
        Self {
            color,
            piece_colors: Vec::new(),
            diffuse: 0.9,
            specular: 0.2,
        }
    }

    /// The colour of piece `k`: its own, or the base colour.
    pub fn piece_color(&self, k: usize) -> [f32; 3] {
        self.piece_colors.get(k).copied().unwrap_or(self.color)
    }

    /// Maslova's Phong coefficients on a PBR material: the diffuse coefficient scales the
    /// albedo; the specular coefficient raises the reflectance (F0) and lowers the
    /// roughness, so the highlight grows stronger and tighter. Double-sided: back faces
    /// are lit with their own normals (Sladović 2014 §3.5), not as a mirror of the front.
    pub fn material(&self) -> StandardMaterial {
        // With piece colours the mesh's vertex colours carry the hue (Bevy multiplies
        // them with the base colour).
        let color = if self.piece_colors.is_empty() {
            self.color
        } else {
            [1.0; 3]
        };
        let [r, g, b] = color.map(|c| c * self.diffuse);
        StandardMaterial {
            base_color: Color::linear_rgb(r, g, b),
            reflectance: self.specular,
            perceptual_roughness: 1.0 - 0.75 * self.specular,
            double_sided: true,
            cull_mode: None,
            ..default()
        }
    }
}

/// The directional light's direction and strength, as the panel edits them.
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
pub struct LightControls {
    /// Angle about the vertical, degrees.
    pub yaw: f32,
    /// Height above the horizon, degrees.
    pub elevation: f32,
    /// Illuminance, lux.
    pub illuminance: f32,
}

impl Default for LightControls {
    fn default() -> Self {
        Self {
            yaw: 30.0,
            elevation: 45.0,
            illuminance: 9_000.0,
        }
    }
}

#[derive(Resource, Default)]
struct ShowWorldInspector(bool);

/// The panel, the look and light updates, and the world inspector behind a button.
pub struct InspectorPlugin;

impl Plugin for InspectorPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<ShowWorldInspector>()
            .init_resource::<LightControls>()
            .init_resource::<Help>()
            .add_plugins(WorldInspectorPlugin::new().run_if(|show: Res<ShowWorldInspector>| show.0))
            .add_systems(EguiPrimaryContextPass, panel)
            .add_systems(Update, (apply_looks, apply_piece_colors, apply_light));
    }
}

#[allow(clippy::type_complexity)]
/// Writes each piece's colour into the vertex colours of a multi-piece cloth's mesh (again
/// when the colours change or the cloth is rebuilt with a new mesh).
fn apply_piece_colors(
    looks: Query<
        (&ClothLook, &ClothSimulation, &Mesh3d),
        Or<(Changed<ClothLook>, Changed<Mesh3d>)>,
    >,
    mut meshes: ResMut<Assets<Mesh>>,
) {
    for (look, sim, mesh3d) in &looks {
        if look.piece_colors.is_empty() {
            continue;
        }
        let Some(mut mesh) = meshes.get_mut(&mesh3d.0) else {
            continue;
        };
        let mut colors = vec![[1.0f32; 4]; sim.solver.particle_count()];
        for (k, (_, range)) in sim.solver.pieces().iter().enumerate() {
            let [r, g, b] = look.piece_color(k);
            for c in &mut colors[range.start as usize..range.end as usize] {
                *c = [r, g, b, 1.0];
            }
        }
        mesh.insert_attribute(Mesh::ATTRIBUTE_COLOR, colors);
    }
}

fn apply_looks(
    looks: Query<(&ClothLook, &MeshMaterial3d<StandardMaterial>), Changed<ClothLook>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
) {
    for (look, handle) in &looks {
        if let Some(mut material) = materials.get_mut(&handle.0) {
            *material = look.material();
        }
    }
}

fn apply_light(
    controls: Res<LightControls>,
    mut lights: Query<(&mut Transform, &mut DirectionalLight)>,
) {
    if !controls.is_changed() {
        return;
    }
    for (mut transform, mut light) in &mut lights {
        let (yaw, elevation) = (controls.yaw.to_radians(), controls.elevation.to_radians());
        let toward_light = Vec3::new(
            yaw.sin() * elevation.cos(),
            elevation.sin(),
            yaw.cos() * elevation.cos(),
        );
        *transform =
            Transform::from_translation(toward_light * 8.0).looking_at(Vec3::ZERO, Vec3::Y);
        light.illuminance = controls.illuminance;
    }
}

/// The keys and mouse buttons, shown along the bottom of the window (an example with
/// other keys inserts its own).
#[derive(Resource)]
pub struct Help(pub &'static str);

impl Default for Help {
    fn default() -> Self {
        Self(
            "W/A/S/D/Q/E rotate · keypad +/− zoom · O/P wind · keypad 2/4/6/8 wind direction · \
G gravity · Space pause · N step · R reset · left-drag grab · right-drag cut · Esc quit",
        )
    }
}

#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn panel(
    mut contexts: EguiContexts,
    mut cloths: Query<(
        Entity,
        Option<&Name>,
        &mut Cloth,
        Option<&ClothStats>,
        Option<&mut ClothLook>,
        Option<&ClothInvalid>,
        Option<&ClothSimulation>,
        Option<&mut ClothSleep>,
        Option<&ClothLod>,
    )>,
    mut env: ResMut<ClothEnvironment>,
    mut pause: ResMut<ClothPause>,
    mut light: ResMut<LightControls>,
    mut show_world: ResMut<ShowWorldInspector>,
    mut time: ResMut<Time<Fixed>>,
    help: Res<Help>,
) -> Result {
    let ctx = contexts.ctx_mut()?;
    let mut viewport = egui::Ui::new(
        ctx.clone(),
        "viewport".into(),
        egui::UiBuilder::new()
            .layer_id(egui::LayerId::background())
            .max_rect(ctx.viewport_rect()),
    );
    egui::Panel::bottom("help").show_inside(&mut viewport, |ui| {
        ui.label(help.0);
    });
    // A fixed width: labels that change do not move the 3D view.
    egui::Panel::left("inspector")
        .exact_size(340.0)
        .show_inside(&mut viewport, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.horizontal(|ui| {
                    if ui
                        .button(if pause.paused { "▶ Run" } else { "⏸ Pause" })
                        .clicked()
                    {
                        pause.toggle();
                    }
                    if ui
                        .add_enabled(pause.paused, egui::Button::new("Step"))
                        .clicked()
                    {
                        pause.step_once();
                    }
                    ui.toggle_value(&mut show_world.0, "World inspector");
                });
                let mut step_ms = time.timestep().as_secs_f32() * 1e3;
                if ui
                    .add(slider(&mut step_ms, 4.0..=33.0).text("fixed step, ms"))
                    .changed()
                {
                    time.set_timestep_seconds(step_ms as f64 / 1e3);
                }
                let step_ms = time.timestep().as_secs_f32() * 1e3;
                for (n, (entity, name, mut cloth, stats, look, invalid, sim, sleep, lod)) in
                    cloths.iter_mut().enumerate()
                {
                    ui.separator();
                    let title = name.map_or_else(|| format!("Cloth {entity}"), |n| n.to_string());
                    // One id scope per cloth, so two cloths' widgets never share an id.
                    egui::CollapsingHeader::new(egui::RichText::new(title).heading())
                        .id_salt(entity)
                        .default_open(n == 0)
                        .show(ui, |ui| {
                            if let Some(ClothInvalid(error)) = invalid {
                                ui.colored_label(
                                    egui::Color32::LIGHT_RED,
                                    format!("not simulated: {error}"),
                                );
                            }
                            let mut edited = cloth.clone();
                            cloth_controls(ui, &mut edited);
                            if edited != *cloth {
                                *cloth = edited;
                            }
                            if let Some(lod) = lod {
                                ui.label(format!(
                                    "level of detail {} ({}), {:.0}% of the view's height",
                                    lod.level,
                                    ClothLod::describe(lod.level),
                                    lod.screen_fraction * 100.0
                                ));
                            }
                            if let Some(mut sleep) = sleep {
                                let mut enabled = sleep.enabled;
                                ui.checkbox(&mut enabled, "may sleep when still (1 mm/s for 1 s)");
                                if enabled != sleep.enabled {
                                    sleep.enabled = enabled;
                                }
                            }
                            if let Some(mut look) = look {
                                let mut edited = look.clone();
                                let names: Vec<&str> = sim
                                    .map(|s| {
                                        s.solver.pieces().iter().map(|(n, _)| n.as_str()).collect()
                                    })
                                    .unwrap_or_default();
                                look_controls(ui, &mut edited, &names);
                                if edited != *look {
                                    *look = edited;
                                }
                            }
                            if let Some(stats) = stats {
                                let parts = matches!(cloth.params.model, Model::Patches(_));
                                statistics(ui, stats, step_ms, parts);
                            }
                        });
                }
                ui.separator();
                let mut edited = env.0;
                environment_controls(ui, &mut edited);
                if edited != env.0 {
                    env.0 = edited;
                }
                let mut edited = *light;
                ui.collapsing("Light", |ui| {
                    ui.add(slider(&mut edited.yaw, -180.0..=180.0).text("direction, °"));
                    ui.add(slider(&mut edited.elevation, 5.0..=90.0).text("elevation, °"));
                    ui.add(slider(&mut edited.illuminance, 0.0..=30_000.0).text("intensity, lux"));
                });
                if edited != *light {
                    *light = edited;
                }
            });
        });
    Ok(())
}

/// A family's switch and stiffness; with `rigid`, also XPBD's inextensible setting
/// (stiffness `inf`, compliance 0).
fn family(ui: &mut egui::Ui, name: &str, family: &mut SpringFamily, rigid: bool) {
    ui.horizontal(|ui| {
        ui.checkbox(&mut family.enabled, name);
        let mut inextensible = family.stiffness == f32::INFINITY;
        if rigid && ui.checkbox(&mut inextensible, "∞").changed() {
            family.stiffness = if inextensible { f32::INFINITY } else { 1_000.0 };
        }
        if !family.stiffness.is_finite() {
            if !rigid {
                family.stiffness = 25_000.0; // the explicit models need a finite one
            }
            return;
        }
        ui.add(
            slider(&mut family.stiffness, 0.0..=25_000.0)
                .logarithmic(true)
                .text("N/m"),
        );
    });
}

fn spring_controls(ui: &mut egui::Ui, springs: &mut SpringParams, rigid: bool) {
    family(ui, "structural", &mut springs.structural, rigid);
    family(ui, "shear", &mut springs.shear, rigid);
    family(ui, "bend", &mut springs.bend, rigid);
    family(ui, "diag. bend", &mut springs.bend_diagonal, rigid);
    ui.add(slider(&mut springs.damping, 0.0..=0.05).text("spring damping, N·s/m"));
}

/// A fabric preset in physical units (its masses, springs and bending), or the seeds'
/// per-spring parameters.
fn fabric_controls(ui: &mut egui::Ui, fabric: &mut Option<Fabric>) {
    let name = fabric.map_or("seed springs (per spring)", |f| {
        f.name().unwrap_or("custom")
    });
    egui::ComboBox::from_label("fabric")
        .selected_text(name)
        .show_ui(ui, |ui| {
            ui.selectable_value(fabric, None, "seed springs (per spring)");
            for (name, preset) in Fabric::PRESETS {
                ui.selectable_value(fabric, Some(preset), name);
            }
        });
    if let Some(f) = fabric {
        ui.label(format!(
            "{:.0} g/m², stretch {:.0} N/m, shear {:.0} N/m, bending {:.1} µN·m (bending length {:.1} cm)",
            f.areal_density * 1e3,
            f.stretch,
            f.shear,
            f.bending * 1e6,
            f.bending_length(9.81) * 100.0
        ));
    }
}

fn cloth_controls(ui: &mut egui::Ui, cloth: &mut Cloth) {
    if let ClothShape::Grid {
        width,
        height,
        spacing,
    } = &mut cloth.shape
    {
        ui.add(slider(width, 2..=256).text("width (rebuilds)"));
        ui.add(slider(height, 2..=256).text("height (rebuilds)"));
        ui.add(
            slider(spacing, 0.005..=0.5)
                .logarithmic(true)
                .text("spacing, m"),
        );
    }
    if let ClothShape::Garment { resolution, .. } = &mut cloth.shape {
        ui.add(slider(resolution, 1..=4).text("resolution (rebuilds)"));
    }
    egui::ComboBox::from_label("pins")
        .selected_text(format!("{:?}", cloth.pins))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut cloth.pins, ClothPins::TopCorners, "TopCorners");
            ui.selectable_value(&mut cloth.pins, ClothPins::TopRow, "TopRow");
            ui.selectable_value(&mut cloth.pins, ClothPins::None, "None");
        });
    let p = &mut cloth.params;
    if p.fabric.is_none() {
        let mut grams = p.node_mass * 1e3;
        ui.add(
            slider(&mut grams, 0.001..=1.0)
                .logarithmic(true)
                .text("node mass, g"),
        );
        p.node_mass = grams * 1e-3;
    }
    let current = p.model.kind();
    egui::ComboBox::from_label("model")
        .selected_text(current.name())
        .show_ui(ui, |ui| {
            for kind in ModelKind::ALL {
                if ui.selectable_label(kind == current, kind.name()).clicked() && kind != current {
                    p.model = kind.default_model();
                }
            }
        });
    let garment = matches!(cloth.shape, ClothShape::Garment { .. });
    match &mut p.model {
        model @ (Model::MassSpring | Model::Xpbd(_)) => {
            let rigid = if let Model::Xpbd(xpbd) = model {
                ui.add(
                    slider(&mut xpbd.max_stretch_error, 0.001..=0.1)
                        .logarithmic(true)
                        .text("stretch error target (auto substeps)"),
                );
                ui.checkbox(&mut xpbd.tethers, "tethers to the pins")
                    .on_hover_text("Long-range attachments: no particle farther from its nearest pin than the cloth between them allows (acts when the structural springs are inextensible or strain limited)");
                let mut lines = xpbd.solve == XpbdSolve::Lines;
                if ui
                    .checkbox(&mut lines, "stretch solved along lines")
                    .on_hover_text("Each row and column of structural springs solved exactly every substep (few substeps hold a moving cloth's length); off: each spring once in a sweep")
                    .changed()
                {
                    xpbd.solve = if lines { XpbdSolve::Lines } else { XpbdSolve::Sweep };
                }
                true
            } else {
                false
            };
            fabric_controls(ui, &mut p.fabric);
            if p.fabric.is_none() {
                spring_controls(ui, &mut p.springs, rigid);
            }
            if garment {
                let s = &mut p.springs;
                family(ui, "seam", &mut s.seam, rigid);
                ui.add(slider(&mut s.seam_rest_length, 0.0..=0.05).text("seam length, m"));
                ui.add(slider(&mut s.sew_time, 0.0..=10.0).text("sewing time, s"));
            }
        }
        Model::ShapeMatching(sm) => shape_matching_controls(ui, sm),
        Model::Patches(patch) => {
            ui.add(slider(&mut patch.part_width, 1..=16).text("part width"));
            ui.add(slider(&mut patch.part_height, 1..=16).text("part height"));
            ui.add(
                slider(&mut patch.stiffness, 0.01..=100.0)
                    .logarithmic(true)
                    .text("pull α, N/m"),
            );
            ui.add(slider(&mut patch.exponent, 0.5..=3.0).text("exponent p"));
            ui.add(
                slider(&mut patch.particle_damping_ratio, 0.0..=2.0)
                    .text("particle damping (× critical)"),
            );
            ui.add(slider(&mut patch.part_damping, 0.0..=0.01).text("part damping, N·s/m"));
            egui::ComboBox::from_label("targets")
                .selected_text(format!("{:?}", patch.targets))
                .show_ui(ui, |ui| {
                    ui.selectable_value(
                        &mut patch.targets,
                        PatchTargets::Bilinear,
                        "Bilinear (continuous)",
                    );
                    ui.selectable_value(
                        &mut patch.targets,
                        PatchTargets::PerPart,
                        "Seed (per part, §3.4)",
                    );
                });
            ui.add_enabled(
                patch.targets == PatchTargets::PerPart,
                egui::Checkbox::new(
                    &mut patch.center_correction,
                    "centre correction (seed targets only)",
                ),
            );
            ui.checkbox(&mut patch.tiles, "tiles (no oscillation)");
            ui.label("part springs:");
            spring_controls(ui, &mut p.springs, false);
        }
    }
    ui.add(slider(&mut p.drag, 0.0..=0.01).text("drag, N·s/m"));
    egui::ComboBox::from_label("integrator")
        .selected_text(format!("{:?}", p.integrator))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut p.integrator, Integrator::Verlet, "Verlet");
            ui.selectable_value(
                &mut p.integrator,
                Integrator::SemiImplicitEuler,
                "SemiImplicitEuler",
            );
        });
    ui.horizontal(|ui| {
        let mut auto = matches!(p.substeps, Substeps::Auto { .. });
        ui.checkbox(&mut auto, "auto substeps");
        match (&mut p.substeps, auto) {
            (Substeps::Fixed(_), true) => p.substeps = Substeps::default(),
            (Substeps::Auto { .. }, false) => p.substeps = Substeps::Fixed(8),
            (Substeps::Fixed(n), false) => {
                ui.add(slider(n, 1..=256).logarithmic(true));
            }
            (Substeps::Auto { max }, true) => {
                ui.add(slider(max, 1..=16_384).logarithmic(true).text("max"));
            }
        }
    });
    optional(ui, "strain limit", &mut p.strain_limit, 0.1, 0.01..=1.0);
    // XPBD applies the limit inside its one projection per substep: no sweeps to set.
    if !matches!(p.model, Model::Xpbd(_)) {
        // Fixed sweeps, or sweeps until every spring is within a tolerance of the limit
        // (at most that many).
        optional(
            ui,
            "sweep until within",
            &mut p.strain_limit_tolerance,
            1e-4,
            1e-6..=1e-2,
        );
        let label = match p.strain_limit_tolerance {
            Some(_) => "most limit sweeps",
            None => "limit sweeps",
        };
        ui.add(
            slider(&mut p.strain_limit_iterations, 0..=1000)
                .logarithmic(true)
                .text(label),
        );
    }
    optional(ui, "tear ratio", &mut p.tear_ratio, 2.0, 1.05..=10.0);
    // XPBD and mass-spring only: the other models say so above ("not simulated: …").
    let sc = &mut p.self_collision;
    ui.checkbox(&mut sc.enabled, "self-collision");
    if sc.enabled {
        optional(
            ui,
            "distance, m (else ¾ of the spacing)",
            &mut sc.distance,
            0.01,
            0.001..=0.1,
        );
        ui.add(slider(&mut sc.friction, 0.0..=1.0).text("cloth-on-cloth friction"));
    }
}

fn shape_matching_controls(ui: &mut egui::Ui, sm: &mut ShapeMatchingParams) {
    egui::ComboBox::from_label("rotation")
        .selected_text(match sm.rotation {
            RotationMethod::PolarDecomposition => "polar decomposition",
            RotationMethod::QuaternionAverage => "quaternion average",
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(
                &mut sm.rotation,
                RotationMethod::PolarDecomposition,
                "polar decomposition",
            );
            ui.selectable_value(
                &mut sm.rotation,
                RotationMethod::QuaternionAverage,
                "quaternion average",
            );
        });
    egui::ComboBox::from_label("update")
        .selected_text(format!("{:?}", sm.update))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut sm.update, GoalUpdate::Force, "Force (α, p)");
            ui.selectable_value(&mut sm.update, GoalUpdate::Velocity, "Velocity (Müller)");
        });
    match sm.update {
        GoalUpdate::Force => {
            sm.stiffness = sm.stiffness.max(0.0);
            ui.add(
                slider(&mut sm.stiffness, 0.0..=100.0)
                    .logarithmic(true)
                    .text("α, N/m"),
            );
            ui.add(slider(&mut sm.exponent, 0.5..=3.0).text("exponent p"));
        }
        GoalUpdate::Velocity => {
            sm.stiffness = sm.stiffness.clamp(0.0, 1.0);
            ui.add(slider(&mut sm.stiffness, 0.0..=1.0).text("α per substep"));
        }
    }
    ui.add(slider(&mut sm.damping, 0.0..=0.001).text("particle damping, N·s/m"));
    ui.add(slider(&mut sm.beta, 0.0..=1.0).text("β (linear deformation)"));
    ui.add(slider(&mut sm.clusters, 1..=8).text("clusters k×k"));
}

/// A slider that keeps a value loaded from outside its range (a scene file's 500 limiter
/// sweeps) until the user edits it: egui clamps existing values by default, which changed
/// a scene's parameters just by showing them.
fn slider<N: egui::emath::Numeric>(
    value: &mut N,
    range: std::ops::RangeInclusive<N>,
) -> egui::Slider<'_> {
    egui::Slider::new(value, range).clamping(egui::SliderClamping::Edits)
}

fn optional(
    ui: &mut egui::Ui,
    name: &str,
    value: &mut Option<f32>,
    default: f32,
    range: std::ops::RangeInclusive<f32>,
) {
    ui.horizontal(|ui| {
        let mut on = value.is_some();
        ui.checkbox(&mut on, name);
        match (on, value.as_mut()) {
            (true, Some(v)) => {
                ui.add(slider(v, range).logarithmic(true));
            }
            (true, None) => *value = Some(default),
            (false, _) => *value = None,
        }
    });
}

fn look_controls(ui: &mut egui::Ui, look: &mut ClothLook, pieces: &[&str]) {
    ui.collapsing("Look", |ui| {
        if look.piece_colors.is_empty() {
            ui.horizontal(|ui| {
                ui.label("colour");
                ui.color_edit_button_rgb(&mut look.color);
            });
        }
        for (k, color) in look.piece_colors.iter_mut().enumerate() {
            ui.horizontal(|ui| {
                ui.label(format!(
                    "{} colour",
                    pieces.get(k).copied().unwrap_or("piece")
                ));
                ui.color_edit_button_rgb(color);
            });
        }
        ui.add(slider(&mut look.diffuse, 0.0..=1.0).text("diffuse k_d"));
        ui.add(slider(&mut look.specular, 0.0..=1.0).text("specular k_s"));
    });
}

fn environment_controls(ui: &mut egui::Ui, env: &mut Environment) {
    ui.heading("Environment");
    ui.horizontal(|ui| {
        ui.checkbox(&mut env.gravity_enabled, "gravity");
        ui.add(slider(&mut env.gravity.y, -30.0..=0.0).text("m/s²"));
    });
    let w = &mut env.wind;
    ui.add(slider(&mut w.strength, 0.0..=0.02).text("wind, N per particle"));
    let mut heading = w.direction.x.atan2(w.direction.z).to_degrees();
    if ui
        .add(slider(&mut heading, -180.0..=180.0).text("wind direction, °"))
        .changed()
    {
        let h = heading.to_radians();
        w.direction = Vec3::new(h.sin(), w.direction.y, h.cos()).normalize_or(Vec3::Z);
    }
    let mut trig = w.field == WindField::Trigonometric;
    if ui
        .checkbox(&mut trig, "gusts (Maslova's trigonometric field)")
        .changed()
    {
        w.field = if trig {
            WindField::Trigonometric
        } else {
            WindField::Constant
        };
    }
    // Air in physical units: a velocity along the wind's heading, the force from each
    // triangle's area (the same for any resolution and mass).
    let mut on = env.air.is_some();
    ui.checkbox(
        &mut on,
        "air in physical units (drag and lift on triangles)",
    );
    match (on, &mut env.air) {
        (true, None) => {
            env.air = Some(Air {
                velocity: env.wind.direction.normalize_or(Vec3::Z),
                field: env.wind.field,
                ..Air::default()
            })
        }
        (false, Some(_)) => env.air = None,
        (true, Some(air)) => {
            let mut speed = air.velocity.length();
            ui.add(slider(&mut speed, 0.0..=20.0).text("air speed, m/s (wind's heading)"));
            air.velocity = env.wind.direction.normalize_or(Vec3::Z) * speed;
            air.field = env.wind.field;
            ui.add(slider(&mut air.drag, 0.0..=3.0).text("drag coefficient"));
            ui.add(slider(&mut air.lift, 0.0..=3.0).text("lift coefficient"));
        }
        (false, None) => {}
    }
}

/// The cloth's statistics; `parts`: it runs the patch model, whose springs join parts,
/// not particles (so a curtain counts 1,742 springs as patches and 7,322 as mass-spring).
fn statistics(ui: &mut egui::Ui, stats: &ClothStats, step_ms: f32, parts: bool) {
    ui.heading("Statistics");
    egui::Grid::new(ui.next_auto_id())
        .num_columns(2)
        .show(ui, |ui| {
            let mut row = |name: &str, value: String| {
                ui.label(name);
                ui.label(value);
                ui.end_row();
            };
            row("particles", stats.particles.to_string());
            // Which springs: those that act (a family with stiffness, not torn), between
            // particles, or between the patch model's parts.
            let springs = if parts {
                "springs between parts"
            } else {
                "springs acting"
            };
            row(springs, stats.springs.to_string());
            row("torn springs", stats.torn.to_string());
            row(
                "step time (median 1 s)",
                format!("{:.3} ms", stats.step_ms_median),
            );
            let warn = if stats.under_resolved {
                " (capped: may be unstable)"
            } else {
                ""
            };
            row("substeps", format!("{}{warn}", stats.substeps));
            row(
                "asleep",
                if stats.asleep { "yes (no step)" } else { "no" }.to_string(),
            );
            row("max strain", format!("{:.1} %", stats.max_strain * 100.0));
            row("total energy", format!("{:.4} J", stats.energy.total()));
        });
    // Why a setting is slow or unsafe, rather than a cloth that explodes or a frozen window.
    if stats.under_resolved {
        ui.colored_label(
            egui::Color32::LIGHT_RED,
            format!(
                "The springs are too stiff for the node mass: a stable explicit step needs \
                 ω_max·h < 2, more than the {} substeps allowed. Raise the substep maximum, \
                 lower the stiffness or raise the node mass.",
                stats.substeps
            ),
        );
    } else if stats.step_ms_median > step_ms {
        ui.colored_label(
            egui::Color32::YELLOW,
            format!(
                "Stable, but slower than real time ({:.0}%): stiff springs on light nodes \
                 need {} substeps per {step_ms:.0} ms step (ω_max·h < 2, ω_max² ≈ 2Σk/m).",
                100.0 * step_ms / stats.step_ms_median,
                stats.substeps
            ),
        );
    }
    plot(ui, stats);
}

/// Step time (orange) and total energy (blue) over the last seconds, each scaled to its
/// own range, drawn with egui's painter.
fn plot(ui: &mut egui::Ui, stats: &ClothStats) {
    let (response, painter) =
        ui.allocate_painter(egui::vec2(ui.available_width(), 80.0), egui::Sense::hover());
    let rect = response.rect;
    painter.rect_filled(rect, 2.0, egui::Color32::from_gray(30));
    let samples = &stats.history;
    let (Some(first), Some(last)) = (samples.front(), samples.back()) else {
        return;
    };
    let span = (last.time - first.time).max(1e-3);
    let series = |value: fn(&StatSample) -> f32, color: egui::Color32| {
        let (lo, hi) = samples
            .iter()
            .map(value)
            .fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        let range = (hi - lo).max(1e-9);
        let points = samples
            .iter()
            .map(|s| {
                let x = rect.left() + rect.width() * (s.time - first.time) / span;
                let y = rect.bottom() - rect.height() * (value(s) - lo) / range;
                egui::pos2(x, y)
            })
            .collect();
        painter.line(points, egui::Stroke::new(1.5, color));
    };
    series(|s| s.step_ms, egui::Color32::from_rgb(240, 160, 60));
    series(|s| s.energy, egui::Color32::from_rgb(90, 160, 240));
    ui.label(format!(
        "orange: step time · blue: energy · last {span:.0} s"
    ));
}
