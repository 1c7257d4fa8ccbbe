//! The curtain of seed 000 §3.2: a cloth hanging from its two top corners, swaying under
//! gravity and wind. Orbit camera (left-drag away from the cloth rotates, middle-drag pans,
//! wheel zooms), the seed's keys, mouse tools (left-drag on the cloth grabs, right-drag
//! cuts) and an egui inspector for every parameter.
//!
//! `cargo run --example curtain [-- --scene FILE] [--set key=value]… [--screenshot out.png --frames 120]…`

mod common;

use bevy::prelude::*;
use bevy_cloth::prelude::*;
use bevy_egui::EguiPlugin;
use bevy_panorbit_camera::PanOrbitCameraPlugin;
use common::inspector::InspectorPlugin;
use common::tools::ToolsPlugin;
use common::{ExampleArgs, ScreenshotPlugin};

fn main() {
    let args = ExampleArgs::parse("assets/scenes/curtain.ron");
    let scene = args.load_scene();
    App::new()
        .add_plugins((
            DefaultPlugins.set(common::window_plugin("bevy_cloth — curtain")),
            EguiPlugin::default(),
            PanOrbitCameraPlugin,
            ClothPlugin::default(),
            ClothControlsPlugin,
            InspectorPlugin,
            ToolsPlugin,
            ScreenshotPlugin,
        ))
        .insert_resource(args)
        .insert_resource(ClearColor(Color::srgb(0.62, 0.70, 0.78)))
        .add_systems(
            Startup,
            move |mut commands: Commands,
                  mut meshes: ResMut<Assets<Mesh>>,
                  mut materials: ResMut<Assets<StandardMaterial>>| {
                common::spawn_scene(&scene, &mut commands, &mut materials);
                common::spawn_stage(
                    &mut commands,
                    &mut meshes,
                    &mut materials,
                    Vec3::new(0.0, 1.4, 0.0),
                    3.4,
                );
            },
        )
        .run();
}
