//! A perceptual colour map (viridis, sampled at nine anchors and interpolated linearly) for
//! error heat maps.

const VIRIDIS: [[u8; 3]; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// Colour of `t` in [0, 1] (clamped; NaN maps to the top colour).
pub(crate) fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 1.0 } else { t.clamp(0.0, 1.0) };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    [0, 1, 2].map(|k| (f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * f).round() as u8)
}

/// Colour of a distance `d` clipped at `clip` (0 → dark purple, ≥ clip → yellow).
pub fn distance_color(d: f64, clip: f64) -> [u8; 3] {
    if clip > 0.0 {
        viridis(d / clip)
    } else {
        viridis(1.0)
    }
}

/// [`distance_color`] of every distance, in order (in parallel with the `parallel` feature).
pub fn distance_colors(distances: &[f64], clip: f64) -> Vec<[u8; 3]> {
    crate::parallel::map(distances, &crate::progress::NoProgress, |&d| {
        distance_color(d, clip)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_and_monotone_lightness() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(2.0), viridis(1.0));
        let d: Vec<f64> = (0..20_000).map(|i| f64::from(i) * 1e-4).collect();
        let one_by_one: Vec<[u8; 3]> = d.iter().map(|&x| distance_color(x, 1.5)).collect();
        assert_eq!(distance_colors(&d, 1.5), one_by_one);
        let luma = |c: [u8; 3]| {
            0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
        };
        let mut last = -1.0;
        for i in 0..=100 {
            let l = luma(viridis(f64::from(i) / 100.0));
            assert!(l >= last, "lightness must not decrease");
            last = l;
        }
    }
}
