//! What each stage asks Slurm for: CPUs per task, memory, time limit, partition, account.
//! Defaults per stage, `--partition`/`--account` for all, `--stage STAGE:key=value,...` for one.

use std::collections::BTreeMap;

use anyhow::{Context, Result, bail};

use crate::args::SlurmArgs;
use crate::slurm::plan::Stage;

/// The request of one stage.
#[derive(Debug, Clone, PartialEq)]
pub struct Resources {
    /// `--cpus-per-task`.
    pub cpus: u32,
    /// `--mem` (Slurm syntax: `8G`, `500M`).
    pub mem: String,
    /// `--time` (Slurm syntax: `MM`, `HH:MM:SS`, `D-HH:MM:SS`).
    pub time: String,
    /// `--partition`.
    pub partition: Option<String>,
    /// `--account`.
    pub account: Option<String>,
}

/// The defaults: rendering and the SfM tools use every CPU they get; the report holds the
/// ground truths and their indexes.
fn default_for(stage: Stage) -> Resources {
    let (cpus, mem, time) = match stage {
        Stage::Render => (4, "8G", "04:00:00"),
        Stage::Finalize => (1, "4G", "00:30:00"),
        Stage::Run => (4, "16G", "04:00:00"),
        Stage::Collect => (2, "16G", "02:00:00"),
    };
    Resources {
        cpus,
        mem: mem.into(),
        time: time.into(),
        partition: None,
        account: None,
    }
}

/// A value that goes into an `#SBATCH` line as it is: no spaces, quotes or line breaks.
fn slurm_word(key: &str, v: &str) -> Result<String> {
    if v.is_empty()
        || !v
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_:.,+@".contains(c))
    {
        bail!("{key}='{v}' is not a Slurm value (letters, digits and - _ : . , + @ only)");
    }
    Ok(v.to_string())
}

/// Every stage's resources from the command line.
pub fn resources(a: &SlurmArgs) -> Result<BTreeMap<Stage, Resources>> {
    let mut out = BTreeMap::new();
    for stage in Stage::ALL {
        let mut r = default_for(stage);
        r.partition = a
            .partition
            .as_deref()
            .map(|p| slurm_word("--partition", p))
            .transpose()?;
        r.account = a
            .account
            .as_deref()
            .map(|p| slurm_word("--account", p))
            .transpose()?;
        out.insert(stage, r);
    }
    for spec in &a.stages {
        let (name, kvs) = spec
            .split_once(':')
            .with_context(|| format!("--stage wants STAGE:KEY=VALUE,..., got '{spec}'"))?;
        let stage = Stage::parse(name.trim())?;
        let Some(r) = out.get_mut(&stage) else {
            continue;
        };
        for kv in kvs.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let (k, v) = kv
                .split_once('=')
                .with_context(|| format!("--stage {name}: '{kv}' is not KEY=VALUE"))?;
            let v = slurm_word(k, v.trim())?;
            match k.trim() {
                "cpus" => {
                    r.cpus = v.parse().ok().filter(|&c| c > 0).with_context(|| {
                        format!("--stage {name}: cpus={v} is not a positive integer")
                    })?
                }
                "mem" => r.mem = v,
                "time" => r.time = v,
                "partition" => r.partition = Some(v),
                "account" => r.account = Some(v),
                other => bail!(
                    "--stage {name}: unknown key '{other}' (cpus, mem, time, partition, account)"
                ),
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct T {
        #[command(flatten)]
        s: SlurmArgs,
    }

    fn parse(args: &[&str]) -> Result<BTreeMap<Stage, Resources>> {
        let t = T::try_parse_from(std::iter::once("t").chain(args.iter().copied()))?;
        resources(&t.s)
    }

    #[test]
    fn stage_options_override_the_defaults_of_their_stage_only() {
        let r = parse(&[
            "--partition",
            "batch",
            "--stage",
            "run:cpus=8,mem=32G,time=1-00:00:00,account=lab",
        ])
        .unwrap();
        let run = &r[&Stage::Run];
        assert_eq!(
            (run.cpus, run.mem.as_str(), run.time.as_str()),
            (8, "32G", "1-00:00:00")
        );
        assert_eq!(run.partition.as_deref(), Some("batch"));
        assert_eq!(run.account.as_deref(), Some("lab"));
        assert_eq!(
            r[&Stage::Render],
            Resources {
                partition: Some("batch".into()),
                ..default_for(Stage::Render)
            }
        );
    }

    #[test]
    fn bad_stage_options_are_refused() {
        for (args, msg) in [
            (vec!["--stage", "paint:cpus=2"], "unknown stage 'paint'"),
            (vec!["--stage", "run:gpus=2"], "unknown key 'gpus'"),
            (vec!["--stage", "run:cpus=0"], "cpus=0"),
            (
                vec!["--stage", "run:mem=4G\n#SBATCH --x"],
                "not a Slurm value",
            ),
            (vec!["--partition", "a b"], "not a Slurm value"),
            (vec!["--stage", "run"], "STAGE:KEY=VALUE"),
        ] {
            let e = format!("{:#}", parse(&args).unwrap_err());
            assert!(e.contains(msg), "{args:?}: {e}");
        }
    }
}
