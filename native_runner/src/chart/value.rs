//! The value of one point of a chart: measured, or why there is none.

/// One point's value.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A measured value.
    Ok(f64),
    /// The run failed or was not run: the reason (shown in the tooltip).
    Failed(String),
    /// The run is ok but the metric is absent or not finite.
    Missing(String),
}

impl Value {
    /// A value from an optional number: `None` or non-finite → `Missing`.
    pub fn from_opt(v: Option<f64>, why: &str) -> Value {
        match v {
            Some(x) if x.is_finite() => Value::Ok(x),
            Some(x) => Value::Missing(format!("{why}: {x}")),
            None => Value::Missing(why.to_string()),
        }
    }
}
