//! Output: tidy CSV tables of the records, and figures (feature `plot`).
//!
//! The last stage of the data flow: records made by the samplers and sweeps go out as
//!
//! * [`csv`] — tidy CSV files (always available): one observation per row, a header, SI units
//!   in the column names (`t_s`, `x_m`, `v_m_s`, `interval_s`, `omega_rad_s`), readable by
//!   `pandas.read_csv` without options. Missing values are empty fields (read as `NaN`);
//!   numbers are written in their shortest round-trip form, so a value read back is the
//!   value written, bit for bit.
//! * `plot` (feature `plot`) — PNG and SVG figures drawn with `plotters`, in the style of the
//!   paper's figures: bifurcation diagrams of the stroboscopic points
//!   $x(2\pi i/\omega)$ and of the inter-impact intervals $T_j$ against the parameter
//!   (increasing sweep red, decreasing green, small dots), phase portraits $(x, \dot x)$ with
//!   the stop $x = x_I$ as a red line, time profiles $x(t)$, and generic line, scatter, stem and
//!   bar charts. Text uses the DejaVu Sans font bundled with the crate, so figures look the
//!   same on every machine and need no system fonts.
//!
//! Every writer takes an [`std::io::Write`] and has a `*_path` twin that creates the parent
//! directories and names the file in its error. Errors are [`Error::Output`](crate::Error::Output).
//!
//! Nothing here is used by the computations: output only reads records.

pub mod csv;
#[cfg(feature = "plot")]
pub mod plot;

use std::path::Path;

/// Creates the parent directories of `path` (if any).
pub(crate) fn create_parent(path: &Path) -> crate::Result<()> {
    if let Some(parent) = path.parent() {
        if !parent.as_os_str().is_empty() {
            std::fs::create_dir_all(parent).map_err(|e| {
                crate::Error::Output(format!(
                    "{}: cannot create directory {}: {e}",
                    path.display(),
                    parent.display()
                ))
            })?;
        }
    }
    Ok(())
}
