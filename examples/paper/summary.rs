//! The summary table: one row per number the paper reports, beside ours.
#![allow(clippy::too_many_arguments)]

use std::fmt::Write as _;

/// One reported number.
#[derive(Debug, Clone)]
pub struct Row {
    pub id: String,
    pub quantity: String,
    pub unit: String,
    pub paper: Option<f64>,
    pub ours: Option<f64>,
    pub verdict: String,
}

impl Row {
    pub fn rel_diff(&self) -> Option<f64> {
        match (self.paper, self.ours) {
            (Some(p), Some(o)) if p != 0.0 => Some((o - p) / p.abs()),
            (Some(p), Some(o)) if p == 0.0 => Some(o - p),
            _ => None,
        }
    }
}

/// Collects rows.
#[derive(Debug, Default)]
pub struct Summary {
    pub rows: Vec<Row>,
}

impl Summary {
    /// A number compared with the paper at a relative tolerance (`rtol`, e.g. half a unit of
    /// the last printed digit); `reason` explains a difference.
    pub fn compare(
        &mut self,
        id: &str,
        quantity: &str,
        unit: &str,
        paper: f64,
        ours: Option<f64>,
        rtol: f64,
        reason: &str,
    ) {
        let verdict = match ours {
            None => format!("not computed: {reason}"),
            Some(o) => {
                let rel = if paper != 0.0 {
                    ((o - paper) / paper).abs()
                } else {
                    (o - paper).abs()
                };
                if rel <= rtol {
                    "reproduced".to_string()
                } else if reason.is_empty() {
                    format!("differs ({:.2} % off)", rel * 100.0)
                } else {
                    format!("differs ({:.2} % off): {reason}", rel * 100.0)
                }
            }
        };
        self.rows.push(Row {
            id: id.into(),
            quantity: quantity.into(),
            unit: unit.into(),
            paper: Some(paper),
            ours,
            verdict,
        });
    }

    /// As [`compare`](Self::compare), with the verdict prefixed by what the value is (e.g.
    /// the kind of a bifurcation).
    pub fn compare_located(
        &mut self,
        id: &str,
        quantity: &str,
        paper: f64,
        ours: Option<f64>,
        rtol: f64,
        what: &str,
    ) {
        self.compare(id, quantity, "rad/s", paper, ours, rtol, "");
        if let Some(row) = self.rows.last_mut() {
            row.verdict = format!("{what}; {}", row.verdict);
        }
    }

    /// A number the paper gives only as a sign or qualitatively.
    pub fn qualitative(
        &mut self,
        id: &str,
        quantity: &str,
        unit: &str,
        ours: Option<f64>,
        ok: bool,
        expectation: &str,
    ) {
        let verdict = match ours {
            None => format!("not computed ({expectation})"),
            Some(_) if ok => format!("reproduced ({expectation})"),
            Some(_) => format!("differs (paper: {expectation})"),
        };
        self.rows.push(Row {
            id: id.into(),
            quantity: quantity.into(),
            unit: unit.into(),
            paper: None,
            ours,
            verdict,
        });
    }

    pub fn to_json(&self) -> String {
        let rows: Vec<serde_json::Value> = self
            .rows
            .iter()
            .map(|r| {
                serde_json::json!({
                    "id": r.id,
                    "quantity": r.quantity,
                    "unit": r.unit,
                    "paper": r.paper,
                    "ours": r.ours.filter(|v| v.is_finite()),
                    "rel_diff": r.rel_diff().filter(|v| v.is_finite()),
                    "verdict": r.verdict,
                })
            })
            .collect();
        serde_json::to_string_pretty(&rows).unwrap_or_default()
    }

    pub fn to_markdown(&self) -> String {
        let mut s = String::from(
            "| id | quantity | unit | paper | ours | rel. diff | verdict |\n|---|---|---|---|---|---|---|\n",
        );
        let f = |v: Option<f64>| v.map(|x| format!("{x:.6}")).unwrap_or_else(|| "—".into());
        let g = |v: Option<f64>| v.map(|x| format!("{x:.5e}")).unwrap_or_else(|| "—".into());
        for r in &self.rows {
            let small = r
                .paper
                .map(|p| p != 0.0 && (p.abs() < 1e-2 || p.abs() >= 1e4))
                .unwrap_or(false)
                || r.ours
                    .map(|o| o != 0.0 && (o.abs() < 1e-2 || o.abs() >= 1e4))
                    .unwrap_or(false);
            let fmt = if small { g } else { f };
            let _ = writeln!(
                s,
                "| `{}` | {} | {} | {} | {} | {} | {} |",
                r.id,
                r.quantity,
                r.unit,
                fmt(r.paper),
                fmt(r.ours),
                r.rel_diff()
                    .map(|d| format!("{:+.2e}", d))
                    .unwrap_or_else(|| "—".into()),
                r.verdict
            );
        }
        s
    }
}
