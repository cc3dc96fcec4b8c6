//! Numbers as the page's Compare table writes them: whole numbers in full, others with four
//! significant digits, in exponent form below 1e-3 and from 1e5 — JavaScript's `String`,
//! `toPrecision(4)` and `toExponential(3)`, digit for digit (decimal rounding of the exact
//! binary value, halves up), so that the text is the same wherever it is made.

/// The page's text of a number: `—` for none or NaN.
pub fn compact(v: Option<f64>) -> String {
    let Some(x) = v else {
        return "—".into();
    };
    if x.is_nan() {
        return "—".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "Infinity" } else { "-Infinity" }.into();
    }
    if x.fract() == 0.0 {
        return js_integer(x);
    }
    let a = x.abs();
    if !(1e-3..1e5).contains(&a) {
        to_exponential(x, 3)
    } else {
        to_precision(x, 4)
    }
}

/// JavaScript's `String` of a whole number (`-0` is `0`, from 1e21 in exponent form).
fn js_integer(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    if x.abs() < 1e21 {
        return format!("{x:.0}");
    }
    // shortest round-trip digits, as JavaScript's exponent form: 1e+21, 1.5e+22
    let s = format!("{x:e}");
    match s.split_once('e') {
        Some((m, e)) if !e.starts_with('-') => format!("{m}e+{e}"),
        _ => s,
    }
}

/// The first `p` significant digits of `a` > 0 rounded half up on its exact decimal value, and
/// the exponent of the first one.
fn significant(a: f64, p: usize) -> (Vec<u8>, i32) {
    // an f64's exact decimal expansion has at most 767 significant digits
    let s = format!("{a:.800e}");
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let mut e: i32 = exp.parse().unwrap_or(0);
    let all: Vec<u8> = mantissa
        .bytes()
        .filter(u8::is_ascii_digit)
        .map(|b| b - b'0')
        .collect();
    let mut d: Vec<u8> = all.iter().copied().take(p).collect();
    if all.get(p).is_some_and(|&n| n >= 5) {
        let mut i = p;
        loop {
            if i == 0 {
                d.insert(0, 1);
                d.truncate(p);
                e += 1;
                break;
            }
            i -= 1;
            if d[i] == 9 {
                d[i] = 0;
            } else {
                d[i] += 1;
                break;
            }
        }
    }
    (d, e)
}

fn digits_text(d: &[u8]) -> String {
    d.iter().map(|n| char::from(b'0' + n)).collect()
}

fn exponent_form(d: &[u8], e: i32) -> String {
    let rest = digits_text(&d[1..]);
    let sign = if e < 0 { '-' } else { '+' };
    let point = if rest.is_empty() { "" } else { "." };
    format!("{}{point}{rest}e{sign}{}", d[0], e.abs())
}

/// JavaScript's `x.toExponential(f)` for a finite, non-zero `x`.
pub fn to_exponential(x: f64, f: usize) -> String {
    let (d, e) = significant(x.abs(), f + 1);
    let sign = if x < 0.0 { "-" } else { "" };
    format!("{sign}{}", exponent_form(&d, e))
}

/// JavaScript's `x.toPrecision(p)` for a finite, non-zero `x`.
pub fn to_precision(x: f64, p: usize) -> String {
    let (d, e) = significant(x.abs(), p);
    let sign = if x < 0.0 { "-" } else { "" };
    let p = p as i32;
    let body = if e < -6 || e >= p {
        exponent_form(&d, e)
    } else if e >= 0 {
        let cut = (e + 1) as usize;
        let (int, frac) = d.split_at(cut);
        if frac.is_empty() {
            digits_text(int)
        } else {
            format!("{}.{}", digits_text(int), digits_text(frac))
        }
    } else {
        format!("0.{}{}", "0".repeat((-e - 1) as usize), digits_text(&d))
    };
    format!("{sign}{body}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn as_javascript_writes_them() {
        // each right-hand side is what Node 20 prints for the page's formatting of the number
        for (x, js) in [
            (36.0, "36"),
            (-0.0, "0"),
            (0.0, "0"),
            (1e21, "1e+21"),
            (0.0123456, "0.01235"),
            (0.001, "0.001000"),
            (0.00099999, "1.000e-3"),
            (0.000123456, "1.235e-4"),
            (123456.7, "1.235e+5"),
            (99999.99, "1.000e+5"),
            (12345.6, "1.235e+4"),
            (1234.56, "1235"),
            (0.5, "0.5000"),
            (-0.33333, "-0.3333"),
            (0.00125, "0.001250"),
            (1.0005, "1.000"),
            (0.125, "0.1250"),
            (2.5e-7, "2.500e-7"),
        ] {
            assert_eq!(compact(Some(x)), js, "{x}");
        }
        assert_eq!(compact(None), "—");
        assert_eq!(compact(Some(f64::NAN)), "—");
        // halves round up (2.5 → 3, where Rust's own formatting gives 2)
        assert_eq!(to_precision(1.00025, 4), "1.000");
        assert_eq!(to_precision(1.5, 1), "2");
        assert_eq!(to_precision(2.5, 1), "3");
        assert_eq!(to_exponential(9.9995e-4, 3), "1.000e-3");
    }
}
