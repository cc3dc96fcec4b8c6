//! The `.mat` reader on files scipy wrote (`data/make_fixtures.py`): the values the script
//! saved, compressed and not, and every truncation of them refused without a panic.
#![allow(clippy::unwrap_used)]

use sfmeval_dtu::mat::{MatClass, MatData, read_mat};

const RAW: &[u8] = include_bytes!("data/obsmask_raw.mat");
const Z: &[u8] = include_bytes!("data/obsmask_z.mat");
const PLANE: &[u8] = include_bytes!("data/plane.mat");

#[test]
fn reads_what_scipy_saved() {
    for bytes in [RAW, Z] {
        let mat = read_mat(bytes).unwrap();
        let mask = mat.get("ObsMask").unwrap();
        assert_eq!(mask.dims, vec![5, 4, 3]);
        assert_eq!(mask.class, MatClass::Uint8);
        assert!(mask.logical);
        let MatData::U8(cells) = &mask.data else {
            panic!("a logical array is read as bytes")
        };
        // Column-major: (i, j, k) at i + 5 (j + 4 k).
        let set: Vec<usize> = (0..cells.len()).filter(|&c| cells[c] != 0).collect();
        let mut expected = vec![1 + 5 * 2, 4 + 5 * (3 + 4 * 2), 5 * (1 + 4)];
        expected.sort();
        assert_eq!(set, expected);
        let bb = mat.get("BB").unwrap();
        assert_eq!(bb.dims, vec![2, 3]);
        assert_eq!(bb.to_f64(), vec![-10.5, 20.0, 0.25, 30.5, 3.0, 40.125]);
        assert_eq!(mat.get("Res").unwrap().to_f64(), vec![0.2]);
    }
    let p = read_mat(PLANE).unwrap();
    assert_eq!(p.get("P").unwrap().dims, vec![4, 1]);
    assert_eq!(p.get("P").unwrap().to_f64(), vec![0.1, -0.2, 0.97, -5.0]);
}

#[test]
fn truncations_fail_or_hold_fewer_variables() {
    for bytes in [RAW, Z, PLANE] {
        let all = read_mat(bytes).unwrap().arrays.len();
        for cut in 0..bytes.len() {
            if let Ok(m) = read_mat(&bytes[..cut]) {
                assert!(m.arrays.len() < all, "cut at {cut} of {}", bytes.len());
            }
        }
    }
}
