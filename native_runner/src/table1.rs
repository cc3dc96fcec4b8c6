//! `sfmeval-runner table1`: the seed experiment in one command. Renders the five built-in
//! datasets with the Blender generator (`blender_scripts/generate.py` in the venv's bpy), runs
//! every pipeline on them and writes the comparison table. `--quick` renders them with the
//! small preset's settings (36 views, 640×360, 16 spp). Rendered datasets and finished runs
//! are reused unless `--fresh`.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};

use crate::args::Table1Args;
use crate::dataset::Dataset;
use crate::generator::{find_blender_scripts, render_dataset};
use crate::summary::{Executor, Table1Summary, Table1Timing, render_times, write_summary};

/// The seed paper's five datasets, as generator presets.
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

/// Renders one preset into `dest` (through a temporary folder), returning the seconds spent.
fn generate(
    python: &Path,
    scripts: &Path,
    preset: &str,
    quick: bool,
    sets: &[String],
    dest: &Path,
) -> Result<f64> {
    let args = generator_args(preset, quick, sets);
    render_dataset("table1", python, scripts, &args, dest)
}

/// The whole experiment.
pub fn table1(a: &Table1Args) -> Result<()> {
    let t0 = Instant::now();
    a.exec.check()?;
    a.slurm.check_local(a.resume)?;
    let python = crate::env::find_python(a.tools.python.as_deref())?;
    let scripts = std::path::absolute(find_blender_scripts(
        a.generator.blender_scripts.as_deref(),
    )?)?;
    let presets = presets(a);
    // Absolute: the generator runs inside the datasets folder, so a relative --out would
    // land one level too deep.
    let out = std::path::absolute(&a.out)
        .with_context(|| format!("resolving --out {}", a.out.display()))?;
    let ds_root = out.join("datasets");
    let runs = out.join("runs");
    let table = out.join("table");
    std::fs::create_dir_all(&ds_root).with_context(|| format!("creating {}", ds_root.display()))?;
    let mut gen_times = std::collections::BTreeMap::new();
    let mut datasets = Vec::new();
    for p in &presets {
        let name = dataset_name(p, a.quick);
        let dest = ds_root.join(&name);
        let complete = dest.join("dataset.json").is_file() && dest.join("cameras.json").is_file();
        if complete && !a.generator.fresh {
            eprintln!("table1: reusing {}", dest.display());
        } else {
            let secs = generate(&python, &scripts, p, a.quick, &a.generator.sets, &dest)?;
            gen_times.insert(name.clone(), secs);
        }
        datasets.push(Dataset::open(&dest)?);
    }
    for scene in &a.scenes {
        let ds = Dataset::open(scene)?;
        if !crate::tnt::is_scene(&ds.dir, &ds.name) {
            anyhow::bail!(
                "--scene {}: no {name}_trans.txt and {name}_COLMAP_SfM.log in it (the Tanks and Temples layout, folder named after the scene)",
                scene.display(),
                name = ds.name
            );
        }
        datasets.push(ds);
    }
    let gen_seconds = t0.elapsed().as_secs_f64();
    let customs = crate::pipelines::parse_customs(&a.tools.customs)?;
    let specs = crate::pipelines::parse_list(&a.pipelines, &customs)?;
    let env = crate::env::make_env(&a.tools, &runs)?;
    let opts = a.exec.batch_options(&runs, !a.generator.fresh, false)?;
    let t_runs = Instant::now();
    let summary = crate::run::run_batch(&datasets, &specs, &customs, &env, &opts)?;
    let runs_seconds = t_runs.elapsed().as_secs_f64();
    let t_rep = Instant::now();
    let rows = crate::report::report(&a.eval.report_args(&runs, &table)?)?;
    let report_seconds = t_rep.elapsed().as_secs_f64();
    // per view: what the generator measured, for the datasets rendered now
    let (_, per_view) = render_times(gen_times.keys().map(|n| (n.as_str(), ds_root.join(n))));
    let doc = Table1Summary {
        quick: a.quick,
        presets,
        pipelines: specs.iter().map(|s| s.name.clone()).collect(),
        executor: Executor::Local,
        runs_executed: summary.ran,
        runs_reused: summary.skipped,
        tasks_without_result: Vec::new(),
        timing: Table1Timing {
            render_seconds: gen_times,
            render_seconds_per_view: per_view,
            datasets_seconds: gen_seconds,
            runs_seconds,
            report_seconds,
            total_seconds: t0.elapsed().as_secs_f64(),
        },
    };
    write_summary(&out.join("table1.json"), &doc)?;
    let t1 = std::fs::read_to_string(table.join("table1.md")).unwrap_or_default();
    println!("{t1}");
    eprintln!(
        "table1: {} runs; datasets {:.0} s, runs {:.0} s, report {:.0} s, total {:.0} s; tables in {}",
        rows.len(),
        gen_seconds,
        runs_seconds,
        report_seconds,
        t0.elapsed().as_secs_f64(),
        table.display()
    );
    Ok(())
}
