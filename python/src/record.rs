//! Results as plain values, built on the worker thread and turned into a Python dict of
//! numpy arrays with the GIL.

use std::collections::BTreeMap;

use nalgebra::{Complex, SMatrix, SVector};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// One value of a result.
#[derive(Debug, Clone)]
pub enum Val {
    F(f64),
    I(i64),
    B(bool),
    S(String),
    None,
    /// A float array of the given shape (row-major).
    A(Vec<f64>, Vec<usize>),
    /// A complex array (1-D).
    C(Vec<Complex<f64>>),
    /// A list of records.
    L(Vec<Rec>),
}

/// A result: named values.
#[derive(Debug, Clone, Default)]
pub struct Rec(pub BTreeMap<&'static str, Val>);

impl Rec {
    pub fn new() -> Self {
        Self::default()
    }
    pub fn f(mut self, k: &'static str, v: f64) -> Self {
        self.0.insert(k, Val::F(v));
        self
    }
    pub fn i(mut self, k: &'static str, v: impl TryInto<i64>) -> Self {
        self.0.insert(k, Val::I(v.try_into().unwrap_or(i64::MAX)));
        self
    }
    pub fn b(mut self, k: &'static str, v: bool) -> Self {
        self.0.insert(k, Val::B(v));
        self
    }
    pub fn s(mut self, k: &'static str, v: impl Into<String>) -> Self {
        self.0.insert(k, Val::S(v.into()));
        self
    }
    pub fn none(mut self, k: &'static str) -> Self {
        self.0.insert(k, Val::None);
        self
    }
    pub fn opt(self, k: &'static str, v: Option<f64>) -> Self {
        match v {
            Some(v) => self.f(k, v),
            None => self.none(k),
        }
    }
    pub fn a1(mut self, k: &'static str, v: Vec<f64>) -> Self {
        let n = v.len();
        self.0.insert(k, Val::A(v, vec![n]));
        self
    }
    /// A row-major array of the given shape.
    pub fn shaped(mut self, k: &'static str, flat: Vec<f64>, shape: Vec<usize>) -> Self {
        self.0.insert(k, Val::A(flat, shape));
        self
    }
    /// Rows of `M` components as an `n × M` array.
    pub fn rows<const M: usize>(mut self, k: &'static str, rows: &[SVector<f64, M>]) -> Self {
        let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
        self.0.insert(k, Val::A(flat, vec![rows.len(), M]));
        self
    }
    pub fn vec<const M: usize>(self, k: &'static str, v: &SVector<f64, M>) -> Self {
        self.a1(k, v.iter().copied().collect())
    }
    pub fn matrix<const M: usize>(mut self, k: &'static str, m: &SMatrix<f64, M, M>) -> Self {
        // Row-major.
        let flat: Vec<f64> = (0..M)
            .flat_map(|i| (0..M).map(move |j| m[(i, j)]))
            .collect();
        self.0.insert(k, Val::A(flat, vec![M, M]));
        self
    }
    pub fn complex(mut self, k: &'static str, v: Vec<Complex<f64>>) -> Self {
        self.0.insert(k, Val::C(v));
        self
    }
    pub fn list(mut self, k: &'static str, v: Vec<Rec>) -> Self {
        self.0.insert(k, Val::L(v));
        self
    }
    pub fn stats(self, s: &nonsmooth::integrate::Stats) -> Self {
        self.list(
            "stats",
            vec![
                Rec::new()
                    .i("rhs_evals", s.rhs_evals)
                    .i("accepted", s.accepted)
                    .i("rejected", s.rejected)
                    .i("events", s.events),
            ],
        )
    }

    /// The dict.
    pub fn into_py<'py>(self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in self.0 {
            d.set_item(k, val(py, v)?)?;
        }
        Ok(d)
    }
}

fn val(py: Python<'_>, v: Val) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Val::F(x) => x.into_pyobject(py)?.into_any().unbind(),
        Val::I(x) => x.into_pyobject(py)?.into_any().unbind(),
        Val::B(x) => x.into_pyobject(py)?.to_owned().into_any().unbind(),
        Val::S(x) => x.into_pyobject(py)?.into_any().unbind(),
        Val::None => py.None(),
        Val::A(flat, shape) => {
            let a = PyArray1::from_vec(py, flat);
            if shape.len() == 1 {
                a.into_any().unbind()
            } else {
                a.reshape(shape)?.into_any().unbind()
            }
        }
        Val::C(c) => {
            let c: Vec<numpy::Complex64> = c
                .iter()
                .map(|z| numpy::Complex64::new(z.re, z.im))
                .collect();
            PyArray1::from_vec(py, c).into_any().unbind()
        }
        Val::L(list) => {
            let items: Vec<Bound<'_, PyDict>> = list
                .into_iter()
                .map(|r| r.into_py(py))
                .collect::<PyResult<_>>()?;
            PyList::new(py, items)?.into_any().unbind()
        }
    })
}
