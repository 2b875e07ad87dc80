//! The golden values of the Python tests, computed by the paper example's own functions
//! (`examples/paper/reproduce.rs`, the code behind `tests/paper.rs` and `cargo run
//! --example paper`): the Poincaré points and impact count of the attractor at
//! ω = 20.465 rad/s, its entropy index q and its top Lyapunov exponent, as the bits of each
//! number. `tests/golden.json` holds them; this test checks that the crate still gives
//! them, and `tests/test_golden.py` that the Python package gives the same bits.
//!
//! Regenerate after a change of the engine that moves the numbers:
//! `NONSMOOTH_WRITE_GOLDEN=1 cargo test --release -p nonsmooth-python --test golden`.

#[allow(unused_imports)]
#[path = "../../examples/paper/reproduce.rs"]
mod reproduce;

use serde_json::{Value, json};

const OMEGA: f64 = 20.465;
const RTOL: f64 = 1e-8;
const RECORD: u32 = 1000;
const TLE_TRANSIENT: usize = 100;
const TLE_PERIODS: usize = 300;

fn bits(v: f64) -> String {
    format!("{:016x}", v.to_bits())
}

fn golden() -> Value {
    let p = reproduce::from_rest(OMEGA, RECORD, RTOL).expect("the paper's attractor");
    let e = reproduce::entropy(OMEGA, RECORD, RTOL).expect("its entropy index");
    let q = e.index.expect("an index").q;
    let (tle, spread) =
        reproduce::tle(OMEGA, TLE_TRANSIENT, TLE_PERIODS, RTOL).expect("its exponent");
    json!({
        "omega": OMEGA,
        "rtol": RTOL,
        "transient": 100,
        "record": RECORD,
        "impacts": p.impacts,
        "impacts_per_period": bits(p.impacts_per_period),
        "period": p.regime.period().unwrap_or(0),
        "poincare": p.poincare.iter().map(|y| [bits(y[0]), bits(y[1])]).collect::<Vec<_>>(),
        "intervals": p.intervals.iter().map(|&t| bits(t)).collect::<Vec<_>>(),
        "end_state": [bits(p.end_state[0]), bits(p.end_state[1])],
        "q": bits(q),
        "q_histogram": [0.05, 0.3, 0.001],
        "tle_transient": TLE_TRANSIENT,
        "tle_periods": TLE_PERIODS,
        "tle": bits(tle),
        "tle_spread": bits(spread),
        "readable": { "impacts": p.impacts, "q": q, "tle": tle, "tle_spread": spread },
    })
}

#[test]
fn the_crate_gives_the_golden_values() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden.json");
    let now = golden();
    if std::env::var_os("NONSMOOTH_WRITE_GOLDEN").is_some() {
        let text = serde_json::to_string_pretty(&now).expect("json") + "\n";
        std::fs::write(&path, text).expect("write tests/golden.json");
        return;
    }
    let text = std::fs::read_to_string(&path).expect("tests/golden.json");
    let want: Value = serde_json::from_str(&text).expect("golden json");
    assert_eq!(
        now, want,
        "the crate's numbers moved: regenerate tests/golden.json"
    );
}
