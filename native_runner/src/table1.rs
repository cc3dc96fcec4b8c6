//! `sfmeval-runner table1`: the seed experiment in one command. Renders the five built-in
//! datasets with the Blender generator (`blender_scripts/generate.py` in the venv's bpy), runs
//! every pipeline on them and writes the comparison table. `--quick` renders them with the
//! small preset's settings (36 views, 640×360, 16 spp). Rendered datasets and finished runs
//! are reused unless `--fresh`. Its datasets and their generator arguments are here; the batch
//! is planned by [`crate::batch::plan::Plan::table1`] and run by either executor.

use crate::args::Table1Args;

/// The five datasets of Table I (statue, vase, bicycle, hydrant, vehicle), as generator presets.
pub const PRESETS: [&str; 5] = ["statue", "vase", "bicycle", "hydrant", "vehicle"];

/// Generator overrides of `--quick`: the `small` preset's camera, views and sampling.
pub const QUICK: [&str; 6] = [
    "camera.resolution=[640, 360]",
    "render.samples=16",
    "render.denoise=false",
    "views.fill=1.0",
    "views.orbits=[{elevation_deg=20.0, count=18}, {elevation_deg=45.0, count=18, azimuth_offset_deg=10.0}]",
    "views.sphere.count=0",
];

/// The dataset (folder) name of a preset: `<preset>-quick` with `--quick`.
pub fn dataset_name(preset: &str, quick: bool) -> String {
    if quick {
        format!("{preset}-quick")
    } else {
        preset.to_string()
    }
}

/// The generator's arguments for one preset (without `--out`): the preset, no depth maps or
/// masks, `--quick`'s overrides and the user's `--set`s.
pub fn generator_args(preset: &str, quick: bool, sets: &[String]) -> Vec<String> {
    let mut args: Vec<String> = vec![
        "--preset".into(),
        preset.into(),
        "--set".into(),
        "outputs.depth=false".into(),
        "--set".into(),
        "outputs.masks=false".into(),
    ];
    let mut overrides: Vec<String> = Vec::new();
    if quick {
        overrides.extend(QUICK.iter().map(|s| s.to_string()));
        overrides.push(format!("dataset.name=\"{preset}-quick\""));
    }
    overrides.extend(sets.iter().cloned());
    for s in overrides {
        args.push("--set".into());
        args.push(s);
    }
    args
}

/// The presets of a `table1` command: `--presets`, or all five.
pub fn presets(a: &Table1Args) -> Vec<String> {
    if a.presets.is_empty() {
        PRESETS.iter().map(|s| s.to_string()).collect()
    } else {
        a.presets.clone()
    }
}
