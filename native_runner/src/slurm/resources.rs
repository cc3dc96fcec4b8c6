//! What each stage asks Slurm for: CPUs per task, memory, time limit, partition, account.
//! Defaults per stage, `--partition`/`--account` for all, `--stage STAGE:key=value,...` for one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

use crate::args::SlurmArgs;
use crate::batch::plan::Stage;

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

/// A Slurm client program (`squeue`, `sinfo`, `scontrol`): beside the given sbatch when it
/// is there, else on PATH.
pub fn slurm_program(sbatch: &str, name: &str) -> PathBuf {
    let sbatch_path = Path::new(sbatch);
    match sbatch_path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && dir.join(name).is_file() => dir.join(name),
        _ => PathBuf::from(name),
    }
}

/// Megabytes of a Slurm memory value (`--mem`: a number with an optional K, M, G or T
/// suffix, megabytes without one).
pub fn mem_megabytes(v: &str) -> Option<f64> {
    let v = v.trim();
    let (num, scale) = match v.chars().last()?.to_ascii_uppercase() {
        'K' => (&v[..v.len() - 1], 1.0 / 1024.0),
        'M' => (&v[..v.len() - 1], 1.0),
        'G' => (&v[..v.len() - 1], 1024.0),
        'T' => (&v[..v.len() - 1], 1024.0 * 1024.0),
        _ => (v, 1.0),
    };
    num.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite() && *x >= 0.0)
        .map(|x| x * scale)
}

/// Seconds of a Slurm time value (`MM`, `MM:SS`, `HH:MM:SS`, `D-HH`, `D-HH:MM`,
/// `D-HH:MM:SS`); `None` for no limit (`infinite`, `UNLIMITED`) or what does not parse.
pub fn time_seconds(v: &str) -> Option<u64> {
    let v = v.trim();
    let (days, rest) = match v.split_once('-') {
        Some((d, r)) => (d.parse::<u64>().ok()?, Some(r)),
        None => (0, None),
    };
    let parts: Vec<u64> = rest
        .unwrap_or(v)
        .split(':')
        .map(|p| p.parse::<u64>().ok())
        .collect::<Option<_>>()?;
    let hms = match (rest.is_some(), parts.as_slice()) {
        (false, [m]) => m * 60,
        (false, [m, s]) => m * 60 + s,
        (false, [h, m, s]) | (true, [h, m, s]) => h * 3600 + m * 60 + s,
        (true, [h]) => h * 3600,
        (true, [h, m]) => h * 3600 + m * 60,
        _ => return None,
    };
    Some(days * 86400 + hms)
}

/// One node of a partition as `sinfo -h -N -o '%P|%c|%m|%l'` lists it.
#[derive(Debug, Clone, PartialEq)]
struct PartitionNode {
    /// The partition (without the `*` of the default one).
    partition: String,
    /// Whether it is the default partition.
    default: bool,
    /// CPUs of the node.
    cpus: u32,
    /// Memory of the node in megabytes.
    mem_mb: f64,
    /// The partition's time limit in seconds (`None`: none).
    time_limit: Option<u64>,
}

fn parse_sinfo(text: &str) -> Vec<PartitionNode> {
    text.lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.trim().split('|').collect();
            let [p, c, m, t] = f.as_slice() else {
                return None;
            };
            Some(PartitionNode {
                partition: p.trim_end_matches('*').to_string(),
                default: p.ends_with('*'),
                cpus: c.trim_end_matches('+').parse().ok()?,
                mem_mb: m.trim_end_matches('+').parse().ok()?,
                time_limit: time_seconds(t),
            })
        })
        .collect()
}

/// Refuses a stage whose request no node of its partition can give (more CPUs or memory
/// than any node has, a time above the partition's limit): Slurm would queue it and it
/// would wait forever. `sinfo` is the text of `sinfo -h -N -o '%P|%c|%m|%l'`.
fn check_against(res: &BTreeMap<Stage, Resources>, stages: &[Stage], sinfo: &str) -> Result<()> {
    let nodes = parse_sinfo(sinfo);
    for stage in stages {
        let Some(r) = res.get(stage) else { continue };
        let name = stage.name();
        let part: Vec<&PartitionNode> = nodes
            .iter()
            .filter(|n| match &r.partition {
                Some(p) => &n.partition == p,
                None => n.default,
            })
            .collect();
        let which = r
            .partition
            .as_deref()
            .map_or("the default partition".to_string(), |p| {
                format!("partition {p}")
            });
        if part.is_empty() {
            let mut known: Vec<&str> = nodes.iter().map(|n| n.partition.as_str()).collect();
            known.dedup();
            bail!(
                "stage {name}: sinfo lists no node in {which} (partitions: {})",
                known.join(", ")
            );
        }
        let mem = mem_megabytes(&r.mem)
            .with_context(|| format!("stage {name}: mem={} is not a Slurm memory size", r.mem))?;
        let time = time_seconds(&r.time)
            .with_context(|| format!("stage {name}: time={} is not a Slurm time", r.time))?;
        if !part.iter().any(|n| n.cpus >= r.cpus && n.mem_mb >= mem) {
            let most_cpus = part.iter().map(|n| n.cpus).max().unwrap_or(0);
            let most_mem = part.iter().map(|n| n.mem_mb).fold(0.0, f64::max);
            bail!(
                "stage {name} asks for {} CPUs and {} of memory per task, more than any node of \
                 {which} has (at most {most_cpus} CPUs, {most_mem:.0}M): Slurm would queue it \
                 forever; lower it with --stage {name}:cpus=N,mem=SIZE or choose another \
                 --partition",
                r.cpus,
                r.mem
            );
        }
        if let Some(limit) = part.iter().filter_map(|n| n.time_limit).max()
            && part.iter().all(|n| n.time_limit.is_some())
            && time > limit
        {
            bail!(
                "stage {name} asks for time={} ({time} s), above the time limit of {which} \
                 ({limit} s): lower it with --stage {name}:time=...",
                r.time
            );
        }
    }
    Ok(())
}

/// [`check_against`] the nodes `sinfo` (beside `sbatch`, else on PATH) lists.
pub fn check_partitions(
    res: &BTreeMap<Stage, Resources>,
    stages: &[Stage],
    sbatch: &str,
) -> Result<()> {
    let sinfo = slurm_program(sbatch, "sinfo");
    let out = std::process::Command::new(&sinfo)
        .args(["-h", "-N", "-o", "%P|%c|%m|%l"])
        .output()
        .with_context(|| {
            format!(
                "running {} to check the stages' resources against the partition",
                sinfo.display()
            )
        })?;
    if !out.status.success() {
        bail!(
            "{} failed ({}): {}",
            sinfo.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    check_against(res, stages, &String::from_utf8_lossy(&out.stdout))
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn slurm_sizes_and_times_parse() {
        assert_eq!(mem_megabytes("8G"), Some(8192.0));
        assert_eq!(mem_megabytes("500"), Some(500.0));
        assert_eq!(mem_megabytes("1t"), Some(1048576.0));
        assert_eq!(mem_megabytes("x"), None);
        assert_eq!(time_seconds("30"), Some(1800));
        assert_eq!(time_seconds("30:15"), Some(1815));
        assert_eq!(time_seconds("04:00:00"), Some(14400));
        assert_eq!(time_seconds("1-00:00:00"), Some(86400));
        assert_eq!(time_seconds("2-3"), Some(2 * 86400 + 3 * 3600));
        assert_eq!(time_seconds("infinite"), None);
    }

    #[test]
    fn requests_above_every_node_of_the_partition_are_refused() {
        let sinfo = "debug*|2|8000|infinite\nshort|16|64000|5:00:00\n";
        let r = parse(&["--stage", "run:cpus=2,mem=7G"]).unwrap();
        assert!(check_against(&r, &[Stage::Run], sinfo).is_ok());
        let r = parse(&["--stage", "run:cpus=3"]).unwrap();
        let e = format!("{:#}", check_against(&r, &[Stage::Run], sinfo).unwrap_err());
        assert!(
            e.contains("stage run asks for 3 CPUs") && e.contains("at most 2 CPUs"),
            "{e}"
        );
        // the default 16G of memory fits no node of `debug`, every node of `short`
        let r = parse(&["--stage", "run:cpus=1,partition=short"]).unwrap();
        assert!(check_against(&r, &[Stage::Run], sinfo).is_ok());
        let e = format!(
            "{:#}",
            check_against(&r, &[Stage::Collect], sinfo).unwrap_err()
        );
        assert!(
            e.contains("16G of memory") && e.contains("default partition"),
            "{e}"
        );
        let r = parse(&["--partition", "short", "--stage", "run:time=06:00:00"]).unwrap();
        let e = format!("{:#}", check_against(&r, &[Stage::Run], sinfo).unwrap_err());
        assert!(e.contains("above the time limit of partition short"), "{e}");
        let r = parse(&["--partition", "gpu"]).unwrap();
        let e = format!("{:#}", check_against(&r, &[Stage::Run], sinfo).unwrap_err());
        assert!(
            e.contains("no node in partition gpu (partitions: debug, short)"),
            "{e}"
        );
    }

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
