//! Throws thousands of random mutations of real Tanks and Temples files at the protocol's
//! readers: any panic fails the test; every outcome must be `Ok` or a typed error.

#[path = "../../sfmeval/tests/support/mutate.rs"]
mod support;
use support::{fixture, run};

#[test]
fn tanksandtemples_readers_survive_mutations() {
    use sfmeval_tnt::{matrix, read_log, read_mapping};
    run("Synth_COLMAP_SfM.log", 3000, |b| {
        let _ = read_log(b);
    });
    run("Synth_mapping_reference.txt", 2000, |b| {
        let _ = read_mapping(b);
    });
    run("Synth_trans.txt", 2000, |b| {
        let _ = matrix::parse(b, "trans");
    });
    run("Synth.json", 3000, |b| {
        // A crop that parses can be applied.
        if let Ok(Some(v)) = sfmeval::crop::Crop::parse(b).map(|c| c.volume) {
            let _ = v.contains([0.1, 0.2, 0.3]);
        }
    });
    // The unmutated files read.
    assert_eq!(
        read_log(&fixture("Synth_COLMAP_SfM.log")).unwrap().len(),
        36
    );
    assert_eq!(
        read_mapping(&fixture("Synth_mapping_reference.txt"))
            .unwrap()
            .video_frames[35],
        351
    );
    assert!(matrix::parse(&fixture("Synth_trans.txt"), "trans").is_ok());
    assert!(
        sfmeval::crop::Crop::parse(&fixture("Synth.json"))
            .unwrap()
            .volume
            .is_some()
    );
}
