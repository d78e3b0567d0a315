//! Formatting numbers and markdown tables for the report.

use std::fmt::Write as _;

use super::stats::Stats;

/// An integer with thousands separators: 1,137,720,816.
pub fn int(v: f64) -> String {
    let neg = v < 0.0;
    let digits = format!("{:.0}", v.abs().round());
    let mut out = String::new();
    for (i, ch) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(ch);
    }
    if neg {
        format!("-{out}")
    } else {
        out
    }
}

/// A number with a sensible number of significant digits for a table.
pub fn num(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        "–".into()
    } else if a >= 1e5 {
        int(v)
    } else if a >= 100.0 {
        format!("{v:.1}")
    } else if a >= 1.0 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    }
}

/// "median [min–max]" with the given formatter, "–" without data.
pub fn mmm(s: Option<Stats>, f: fn(f64) -> String) -> String {
    match s {
        Some(s) => format!("{} [{}–{}]", f(s.median), f(s.min), f(s.max)),
        None => "–".into(),
    }
}

/// "×5.49".
pub fn ratio(v: Option<f64>) -> String {
    match v {
        Some(v) if v.is_finite() => format!("×{v:.2}"),
        _ => "–".into(),
    }
}

/// "14 %": a fraction as a whole percentage.
pub fn percent(v: f64) -> String {
    format!("{:.0} %", 100.0 * v)
}

/// A markdown table.
pub fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "| {} |", header.join(" | "));
    let _ = writeln!(
        s,
        "|{}|",
        header.iter().map(|_| "---").collect::<Vec<_>>().join("|")
    );
    for r in rows {
        let cells: Vec<String> = r
            .iter()
            .map(|c| c.replace('|', "\\|").replace('\n', " "))
            .collect();
        let _ = writeln!(s, "| {} |", cells.join(" | "));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_numbers() {
        assert_eq!(int(1_137_720_816.0), "1,137,720,816");
        assert_eq!(int(999.0), "999");
        assert_eq!(int(1000.0), "1,000");
        assert_eq!(int(-1234.4), "-1,234");
        assert_eq!(num(0.8804), "0.8804");
        assert_eq!(num(4.83391), "4.834");
        assert_eq!(ratio(Some(5.4906)), "×5.49");
        assert_eq!(ratio(None), "–");
        let t = table(&["a", "b"], &[vec!["1".into(), "x|y".into()]]);
        assert_eq!(t, "| a | b |\n|---|---|\n| 1 | x\\|y |\n");
    }
}
