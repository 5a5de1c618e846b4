//! Observations in, a validated column table out.

use std::collections::BTreeMap;
use std::io::Read;

use serde::{Deserialize, Serialize};

use crate::StatsError;

/// One observation: named categorical factor levels, named numeric covariates and the response.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Observation {
    /// Factor name → level (e.g. `"surface" → "clay"`).
    pub factors: BTreeMap<String, String>,
    /// Covariate name → value (e.g. `"v_in_n" → -5.9`, in the covariate's own unit).
    pub covariates: BTreeMap<String, f64>,
    /// The response (e.g. the coefficient of restitution, dimensionless).
    pub response: f64,
}

/// One restitution measurement in the paper's design: the convenient input of [`Dataset::from_cor`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorObservation {
    /// Surface name (`clay`, `tape1`, ...).
    pub surface: String,
    /// Incline angle in degrees; used as a categorical level.
    pub angle: f64,
    /// Incoming normal speed in m/s (the covariate).
    pub v_in_n: f64,
    /// Coefficient of restitution (the response), dimensionless.
    pub cor: f64,
}

/// A categorical column: its level per observation and its sorted distinct levels.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Factor {
    /// Column name.
    pub name: String,
    /// Distinct levels, sorted numerically when every level parses as a number, else lexically;
    /// the first is the reference level of the treatment coding.
    pub levels: Vec<String>,
    /// Per observation, the index into `levels`.
    pub codes: Vec<usize>,
}

impl Factor {
    fn new(name: &str, values: &[String]) -> Self {
        let mut levels: Vec<String> = values.to_vec();
        levels.sort();
        levels.dedup();
        let numeric: Option<Vec<f64>> = levels.iter().map(|l| l.trim().parse::<f64>().ok()).collect();
        if let Some(nums) = numeric {
            let mut idx: Vec<usize> = (0..levels.len()).collect();
            idx.sort_by(|&a, &b| nums[a].total_cmp(&nums[b]).then(levels[a].cmp(&levels[b])));
            levels = idx.into_iter().map(|i| levels[i].clone()).collect();
        }
        let codes = values
            .iter()
            .map(|v| levels.iter().position(|l| l == v).unwrap_or(0))
            .collect();
        Factor {
            name: name.to_string(),
            levels,
            codes,
        }
    }

    /// The level of observation `i`.
    pub fn level_of(&self, i: usize) -> &str {
        &self.levels[self.codes[i]]
    }
}

/// A numeric column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Covariate {
    /// Column name.
    pub name: String,
    /// One finite value per observation.
    pub values: Vec<f64>,
}

/// A validated table: one response, any number of named factors and covariates, all of equal length and
/// finite.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dataset {
    response_name: String,
    response: Vec<f64>,
    factors: Vec<Factor>,
    covariates: Vec<Covariate>,
}

fn check_finite(field: &str, values: &[f64]) -> Result<(), StatsError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(row) => Err(StatsError::NonFinite {
            field: field.to_string(),
            row,
        }),
        None => Ok(()),
    }
}

impl Dataset {
    /// A data set holding only a response column.
    pub fn new(response_name: &str, response: Vec<f64>) -> Result<Self, StatsError> {
        check_finite(response_name, &response)?;
        Ok(Dataset {
            response_name: response_name.to_string(),
            response,
            factors: Vec::new(),
            covariates: Vec::new(),
        })
    }

    fn check_new_column(&self, name: &str, len: usize) -> Result<(), StatsError> {
        if self.has_variable(name) {
            return Err(StatsError::UnknownVariable { name: name.to_string() });
        }
        if len != self.response.len() {
            return Err(StatsError::LengthMismatch {
                field: name.to_string(),
                expected: self.response.len(),
                found: len,
            });
        }
        Ok(())
    }

    fn has_variable(&self, name: &str) -> bool {
        name == self.response_name
            || self.factors.iter().any(|f| f.name == name)
            || self.covariates.iter().any(|c| c.name == name)
    }

    /// Adds a categorical column (one level per observation).
    pub fn with_factor<S: AsRef<str>>(mut self, name: &str, values: &[S]) -> Result<Self, StatsError> {
        self.check_new_column(name, values.len())?;
        let values: Vec<String> = values.iter().map(|v| v.as_ref().to_string()).collect();
        self.factors.push(Factor::new(name, &values));
        Ok(self)
    }

    /// Adds a numeric covariate column.
    pub fn with_covariate(mut self, name: &str, values: Vec<f64>) -> Result<Self, StatsError> {
        self.check_new_column(name, values.len())?;
        check_finite(name, &values)?;
        self.covariates.push(Covariate {
            name: name.to_string(),
            values,
        });
        Ok(self)
    }

    /// Builds a data set from row records; every row must carry the same factor and covariate names
    /// as the first.
    pub fn from_observations(response_name: &str, rows: &[Observation]) -> Result<Self, StatsError> {
        let mut data = Dataset::new(response_name, rows.iter().map(|r| r.response).collect())?;
        let Some(first) = rows.first() else {
            return Ok(data);
        };
        for name in first.factors.keys() {
            let mut col = Vec::with_capacity(rows.len());
            for (row, r) in rows.iter().enumerate() {
                let v = r.factors.get(name).ok_or_else(|| StatsError::MissingValue {
                    field: name.clone(),
                    row,
                })?;
                col.push(v.clone());
            }
            data = data.with_factor(name, &col)?;
        }
        for name in first.covariates.keys() {
            let mut col = Vec::with_capacity(rows.len());
            for (row, r) in rows.iter().enumerate() {
                let v = r.covariates.get(name).ok_or_else(|| StatsError::MissingValue {
                    field: name.clone(),
                    row,
                })?;
                col.push(*v);
            }
            data = data.with_covariate(name, col)?;
        }
        for (row, r) in rows.iter().enumerate() {
            if r.factors.len() != first.factors.len() || r.covariates.len() != first.covariates.len() {
                let extra = r
                    .factors
                    .keys()
                    .chain(r.covariates.keys())
                    .find(|k| !data.has_variable(k))
                    .cloned()
                    .unwrap_or_default();
                return Err(StatsError::MissingValue { field: extra, row });
            }
        }
        Ok(data)
    }

    /// The paper's table: response `cor`, factors `surface` and `angle` (degrees, formatted with `{}`,
    /// so 7.5 → `"7.5"`, 15.0 → `"15"`), covariate `v_in_n`.
    pub fn from_cor(rows: &[CorObservation]) -> Result<Self, StatsError> {
        if let Some(row) = rows.iter().position(|r| !r.angle.is_finite()) {
            return Err(StatsError::NonFinite {
                field: "angle".into(),
                row,
            });
        }
        let surface: Vec<&str> = rows.iter().map(|r| r.surface.as_str()).collect();
        let angle: Vec<String> = rows.iter().map(|r| format!("{}", r.angle)).collect();
        Dataset::new("cor", rows.iter().map(|r| r.cor).collect())?
            .with_factor("surface", &surface)?
            .with_factor("angle", &angle)?
            .with_covariate("v_in_n", rows.iter().map(|r| r.v_in_n).collect())
    }

    /// Reads a headed CSV table, taking the named columns as response, factors (text, kept verbatim)
    /// and covariates (numbers).
    pub fn read_csv<R: Read>(
        reader: R,
        response: &str,
        factors: &[&str],
        covariates: &[&str],
    ) -> Result<Self, StatsError> {
        let mut rdr = csv::Reader::from_reader(reader);
        let headers = rdr.headers()?.clone();
        let col = |name: &str| {
            headers
                .iter()
                .position(|h| h == name)
                .ok_or_else(|| StatsError::UnknownVariable { name: name.to_string() })
        };
        let resp_i = col(response)?;
        let fac_i: Vec<usize> = factors.iter().map(|f| col(f)).collect::<Result<_, _>>()?;
        let cov_i: Vec<usize> = covariates.iter().map(|c| col(c)).collect::<Result<_, _>>()?;
        let mut resp = Vec::new();
        let mut fac: Vec<Vec<String>> = vec![Vec::new(); factors.len()];
        let mut cov: Vec<Vec<f64>> = vec![Vec::new(); covariates.len()];
        let num = |rec: &csv::StringRecord, i: usize, name: &str, row: usize| {
            let s = rec.get(i).unwrap_or("");
            s.trim().parse::<f64>().map_err(|_| StatsError::Parse {
                field: name.to_string(),
                row,
                value: s.to_string(),
            })
        };
        for (row, rec) in rdr.records().enumerate() {
            let rec = rec?;
            resp.push(num(&rec, resp_i, response, row)?);
            for (j, &i) in fac_i.iter().enumerate() {
                fac[j].push(rec.get(i).unwrap_or("").to_string());
            }
            for (j, &i) in cov_i.iter().enumerate() {
                cov[j].push(num(&rec, i, covariates[j], row)?);
            }
        }
        let mut data = Dataset::new(response, resp)?;
        for (name, values) in factors.iter().zip(&fac) {
            data = data.with_factor(name, values)?;
        }
        for (name, values) in covariates.iter().zip(cov) {
            data = data.with_covariate(name, values)?;
        }
        Ok(data)
    }

    /// Number of observations.
    pub fn len(&self) -> usize {
        self.response.len()
    }

    /// True when there are no observations.
    pub fn is_empty(&self) -> bool {
        self.response.is_empty()
    }

    /// The response's name.
    pub fn response_name(&self) -> &str {
        &self.response_name
    }

    /// The response values.
    pub fn response(&self) -> &[f64] {
        &self.response
    }

    /// The factor called `name`, if any.
    pub fn factor(&self, name: &str) -> Option<&Factor> {
        self.factors.iter().find(|f| f.name == name)
    }

    /// The covariate called `name`, if any.
    pub fn covariate(&self, name: &str) -> Option<&Covariate> {
        self.covariates.iter().find(|c| c.name == name)
    }

    /// All factors, in the order added.
    pub fn factors(&self) -> &[Factor] {
        &self.factors
    }

    /// All covariates, in the order added.
    pub fn covariates(&self) -> &[Covariate] {
        &self.covariates
    }

    /// The same data with rows reordered: row `i` of the result is row `order[i]` of `self`.
    /// Returns `None` unless `order` is a permutation of `0..len()`.
    pub fn permuted(&self, order: &[usize]) -> Option<Self> {
        let mut seen = vec![false; self.len()];
        if order.len() != self.len() {
            return None;
        }
        for &i in order {
            if i >= seen.len() || std::mem::replace(&mut seen[i], true) {
                return None;
            }
        }
        let mut out = Dataset::new(&self.response_name, order.iter().map(|&i| self.response[i]).collect()).ok()?;
        for f in &self.factors {
            let vals: Vec<&str> = order.iter().map(|&i| f.level_of(i)).collect();
            out = out.with_factor(&f.name, &vals).ok()?;
        }
        for c in &self.covariates {
            out = out
                .with_covariate(&c.name, order.iter().map(|&i| c.values[i]).collect())
                .ok()?;
        }
        Some(out)
    }
}
