//! The spinning sensors a cloud's recovered rings are matched against: every spinning model of
//! `sim`'s catalogue and the older built-in ones (`vlp16`, `hdl64e`, `os1-64`, `os1-128`), each
//! with its nominal beam table (the default settings' pattern: elevations and beam origin offsets)
//! and the column counts its rotation rates and lidar modes give.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use sim::sensor::{SensorSpec, catalogue::ColumnRule};

use super::super::beam_table::{BeamTable, TableRows};

/// A spinning model's nominal table (origin offsets up, sideways and out along the beam included)
/// and its column options.
pub(crate) struct KnownSensor {
    /// TOML model name (`hdl32e`, ...).
    pub model: &'static str,
    /// The default settings' table, rows sorted up (elevations and origin offsets).
    pub rows: TableRows,
    /// The settings of each rotation rate or lidar mode, with the columns they give.
    pub options: Vec<(usize, SensorSpec)>,
    /// The default settings' minimum range, metres ([`BeamTable::min_range_m`]).
    pub min_range_m: f32,
}

/// The spinning models of `sim::sensor::MODELS` (all but the Ibeo, the Hokuyos and `custom`).
pub fn matched_models() -> impl Iterator<Item = &'static str> {
    sim::sensor::MODELS.iter().copied().filter(|m| !matches!(*m, "ibeo-lux" | "utm30lx" | "utm30lx-nodding" | "custom"))
}

/// Every known spinning sensor, built once.
pub(crate) fn known_sensors() -> &'static [KnownSensor] {
    static KNOWN: OnceLock<Vec<KnownSensor>> = OnceLock::new();
    KNOWN.get_or_init(|| matched_models().filter_map(known).collect())
}

fn known(model: &'static str) -> Option<KnownSensor> {
    let spec = SensorSpec::default_for(model).ok()?;
    let pattern = spec.pattern();
    let rows = BeamTable::from_pattern(&pattern).ok()?.rows().ok()?;
    let options = column_options(&spec);
    Some(KnownSensor { model, rows, options, min_range_m: spec.measurement().min_range_m })
}

/// The settings of every rotation rate (and Ouster lidar mode) of `spec`'s model that validates,
/// with the columns each gives.
fn column_options(spec: &SensorSpec) -> Vec<(usize, SensorSpec)> {
    let mut specs: Vec<SensorSpec> = Vec::new();
    match spec {
        SensorSpec::Vlp16(s) => specs.extend(
            (5..=20).map(|f| SensorSpec::Vlp16(sim::sensor::Vlp16Spec { frequency_hz: f as f32, ..s.clone() })),
        ),
        SensorSpec::Hdl64e(s) => specs.extend(
            (5..=20).map(|f| SensorSpec::Hdl64e(sim::sensor::Hdl64eSpec { frequency_hz: f as f32, ..s.clone() })),
        ),
        SensorSpec::Os1_64(s) => {
            for columns in [512, 1024, 2048] {
                for f in [10.0, 20.0] {
                    specs.push(SensorSpec::Os1_64(sim::sensor::Os1Gen1Spec { columns, frequency_hz: f, ..s.clone() }));
                }
            }
        }
        SensorSpec::Os1_128(s) => {
            for columns in [512, 1024, 2048] {
                for f in [10.0, 20.0] {
                    specs.push(SensorSpec::Os1_128(sim::sensor::Os1Spec { columns, frequency_hz: f, ..s.clone() }));
                }
            }
        }
        _ => {
            if let Some((entry, base)) = spec.catalogued() {
                let with = |s: sim::sensor::CatalogueSpec| {
                    let mut out = spec.clone();
                    if let Some(own) = catalogue_spec_mut(&mut out) {
                        *own = s;
                    }
                    out
                };
                match entry.columns {
                    ColumnRule::FiringCycle { .. } => {
                        for &f in entry.rates_hz {
                            specs.push(with(sim::sensor::CatalogueSpec { frequency_hz: Some(f), ..base.clone() }));
                        }
                    }
                    ColumnRule::Modes { modes, .. } => {
                        for &(columns, rates) in modes {
                            for &f in rates {
                                specs.push(with(sim::sensor::CatalogueSpec {
                                    frequency_hz: Some(f),
                                    columns: Some(columns),
                                    ..base.clone()
                                }));
                            }
                        }
                    }
                }
            }
        }
    }
    let mut out: Vec<(usize, SensorSpec)> =
        specs.into_iter().filter(|s| s.validate("sensor").is_ok()).map(|s| (columns_of(&s), s)).collect();
    // One setting per column count (the first: the lowest rate giving it).
    out.sort_by_key(|o| o.0);
    out.dedup_by_key(|o| o.0);
    out
}

/// The catalogue settings inside a catalogued spec.
fn catalogue_spec_mut(spec: &mut SensorSpec) -> Option<&mut sim::sensor::CatalogueSpec> {
    match spec {
        SensorSpec::Hdl32e(s)
        | SensorSpec::Vlp32c(s)
        | SensorSpec::Vls128(s)
        | SensorSpec::Os0_128(s)
        | SensorSpec::Os2_128(s)
        | SensorSpec::Pandar64(s)
        | SensorSpec::PandarXt32(s)
        | SensorSpec::RsHelios5515(s) => Some(s),
        _ => None,
    }
}

/// The columns of a spinning spec without building its pattern.
fn columns_of(spec: &SensorSpec) -> usize {
    match spec {
        SensorSpec::Vlp16(s) => s.columns(),
        SensorSpec::Hdl64e(s) => s.columns(),
        SensorSpec::Os1_64(s) => s.columns as usize,
        SensorSpec::Os1_128(s) => s.columns as usize,
        _ => match spec.catalogued() {
            Some((entry, s)) => s.columns(entry),
            None => spec.pattern().cols,
        },
    }
}

impl KnownSensor {
    /// The column count of the option nearest to `estimate` (within 5 %), if any.
    pub fn columns_near(&self, estimate: f64) -> Option<usize> {
        self.options
            .iter()
            .map(|o| o.0)
            .min_by(|a, b| (*a as f64 - estimate).abs().total_cmp(&(*b as f64 - estimate).abs()))
            .filter(|&c| (c as f64 - estimate).abs() <= 0.05 * estimate)
    }

    /// The beam table of the setting with `columns` columns (built once per model and count).
    pub fn table(&self, columns: usize) -> Option<BeamTable> {
        static TABLES: OnceLock<Mutex<HashMap<(&'static str, usize), BeamTable>>> = OnceLock::new();
        let tables = TABLES.get_or_init(Default::default);
        if let Some(t) = tables.lock().ok()?.get(&(self.model, columns)) {
            return Some(t.clone());
        }
        let spec = &self.options.iter().find(|o| o.0 == columns)?.1;
        let table = BeamTable::from_spec(spec).ok()?;
        tables.lock().ok()?.insert((self.model, columns), table.clone());
        Some(table)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every spinning model is known, with the beams of its table and its factory columns among
    /// its options.
    #[test]
    fn every_spinning_model_is_known_with_its_factory_columns() {
        let known = known_sensors();
        assert_eq!(known.len(), 12);
        for k in known {
            let spec = SensorSpec::default_for(k.model).unwrap();
            let pattern = spec.pattern();
            assert_eq!(k.rows.len(), pattern.rows, "{}", k.model);
            assert!(k.options.iter().any(|o| o.0 == pattern.cols), "{}: {} columns", k.model, pattern.cols);
        }
        let hdl32e = known.iter().find(|k| k.model == "hdl32e").unwrap();
        assert_eq!(hdl32e.columns_near(2160.0), Some(2170));
        assert_eq!(hdl32e.columns_near(10_000.0), None);
        assert_eq!(hdl32e.table(2170).unwrap().cols, 2170);
    }
}
