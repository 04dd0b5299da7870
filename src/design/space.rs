//! The design space a search moves in: which fields of the instrument vary, over what range,
//! and of what kind (continuous, integer, or a list of values).

use rand::{RngExt, SeedableRng};

use crate::engine::RunConfig;

/// How a parameter varies.
#[derive(Debug, Clone, PartialEq)]
pub enum Domain {
    /// Any value in [lo, hi].
    Continuous(f64, f64),
    /// Whole numbers in [lo, hi].
    Integer(i32, i32),
    /// One of the listed values.
    Choice(Vec<f64>),
}

/// One varied field.
#[derive(Debug, Clone, PartialEq)]
pub struct Dimension {
    /// Its path in the run configuration (`instrument.aperture_mm`).
    pub path: String,
    /// Its range.
    pub kind: Domain,
}

impl Dimension {
    /// Parse `PATH=LO:HI` (continuous), `PATH=LO:HI:int` (whole numbers) or `PATH=A,B,C` (a
    /// list). A path without a dot is an instrument field (`aperture_mm`).
    pub fn parse(text: &str) -> Result<Self, String> {
        let (path, range) =
            text.split_once('=').ok_or_else(|| format!("`{text}`: write PATH=LO:HI, PATH=LO:HI:int or PATH=A,B,C"))?;
        let path = if path.contains('.') { path.to_string() } else { format!("instrument.{path}") };
        let number = |s: &str| s.trim().parse::<f64>().map_err(|_| format!("`{text}`: `{s}` is not a number"));
        let kind = if range.contains(':') {
            let parts: Vec<&str> = range.split(':').collect();
            match parts.as_slice() {
                [lo, hi] => Domain::Continuous(number(lo)?, number(hi)?),
                [lo, hi, "int"] => {
                    let (lo, hi) = (number(lo)?, number(hi)?);
                    if lo.fract() != 0.0 || hi.fract() != 0.0 || lo.abs() > 1e9 || hi.abs() > 1e9 {
                        return Err(format!("`{text}`: an integer range needs whole bounds"));
                    }
                    Domain::Integer(lo as i32, hi as i32)
                }
                _ => return Err(format!("`{text}`: write LO:HI or LO:HI:int")),
            }
        } else {
            let mut values = range.split(',').map(number).collect::<Result<Vec<f64>, String>>()?;
            values.sort_by(f64::total_cmp);
            values.dedup();
            Domain::Choice(values)
        };
        let v = Self { path, kind };
        v.check()?;
        Ok(v)
    }

    fn check(&self) -> Result<(), String> {
        let ok = match &self.kind {
            Domain::Continuous(lo, hi) => lo.is_finite() && hi.is_finite() && lo < hi,
            Domain::Integer(lo, hi) => lo < hi,
            Domain::Choice(v) => v.len() >= 2 && v.len() <= 64 && v.iter().all(|x| x.is_finite()),
        };
        if ok { Ok(()) } else { Err(format!("`{}`: the range needs LO < HI, or 2 to 64 finite values", self.path)) }
    }

    /// The value at `u` in [0, 1) of the range (a Latin-hypercube coordinate).
    #[must_use]
    pub fn at(&self, u: f64) -> f64 {
        match &self.kind {
            Domain::Continuous(lo, hi) => lo + u * (hi - lo),
            Domain::Integer(lo, hi) => {
                let n = f64::from(hi - lo + 1);
                f64::from(*lo) + (u * n).floor().min(n - 1.0)
            }
            Domain::Choice(v) => v[((u * v.len() as f64) as usize).min(v.len() - 1)],
        }
    }

    /// The range as egobox's mixed-integer type.
    #[must_use]
    pub fn xtype(&self) -> egobox_ego::XType {
        match &self.kind {
            Domain::Continuous(lo, hi) => egobox_ego::XType::Float(*lo, *hi),
            Domain::Integer(lo, hi) => egobox_ego::XType::Int(*lo, *hi),
            Domain::Choice(v) => egobox_ego::XType::Ord(v.clone()),
        }
    }

    /// Its smallest and largest value.
    #[must_use]
    pub fn bounds(&self) -> (f64, f64) {
        match &self.kind {
            Domain::Continuous(lo, hi) => (*lo, *hi),
            Domain::Integer(lo, hi) => (f64::from(*lo), f64::from(*hi)),
            Domain::Choice(v) => (v[0], v[v.len() - 1]),
        }
    }

    /// Short name for tables (`aperture_mm`).
    #[must_use]
    pub fn name(&self) -> &str {
        self.path.rsplit('.').next().unwrap_or(&self.path)
    }
}

/// `base` with every variable set to its value in `x` (checked as any configuration is).
pub fn configure(base: &RunConfig, vars: &[Dimension], x: &[f64]) -> Result<RunConfig, String> {
    let settings: Vec<(&str, f64)> = vars.iter().zip(x).map(|(v, &x)| (v.path.as_str(), x)).collect();
    crate::sweep::apply(base, &settings)
}

/// A Latin-hypercube sample of `n` points (McKay, Beckman & Conover 1979): each variable's
/// range cut into `n` strata, one point in each, the strata paired at random.
#[must_use]
pub fn latin_hypercube(vars: &[Dimension], n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = rand::rngs::Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut columns: Vec<Vec<f64>> = Vec::with_capacity(vars.len());
    for v in vars {
        let mut strata: Vec<usize> = (0..n).collect();
        for i in (1..n).rev() {
            strata.swap(i, rng.random_range(0..=i));
        }
        columns.push(strata.into_iter().map(|s| v.at((s as f64 + rng.random::<f64>()) / n as f64)).collect());
    }
    (0..n).map(|i| columns.iter().map(|c| c[i]).collect()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variables_parse_and_refuse() {
        let v = Dimension::parse("aperture_mm=40:200").unwrap();
        assert_eq!((v.path.as_str(), v.bounds()), ("instrument.aperture_mm", (40.0, 200.0)));
        let b = Dimension::parse("adc_bits=10:16:int").unwrap();
        assert_eq!(b.kind, Domain::Integer(10, 16));
        let c = Dimension::parse("exposure_s=0.004,0.001,0.002").unwrap();
        assert_eq!(c.kind, Domain::Choice(vec![0.001, 0.002, 0.004]));
        for bad in ["aperture_mm", "aperture_mm=200:40", "aperture_mm=a:b", "adc_bits=10.5:16:int", "x=1"] {
            assert!(Dimension::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_latin_hypercube_fills_every_stratum_once() {
        let vars = [Dimension::parse("a=0:1").unwrap(), Dimension::parse("b=1:8:int").unwrap()];
        let x = latin_hypercube(&vars, 8, 3);
        let mut a: Vec<usize> = x.iter().map(|p| (p[0] * 8.0) as usize).collect();
        a.sort_unstable();
        assert_eq!(a, (0..8).collect::<Vec<_>>());
        let mut b: Vec<f64> = x.iter().map(|p| p[1]).collect();
        b.sort_by(f64::total_cmp);
        assert_eq!(b, (1..=8).map(f64::from).collect::<Vec<_>>());
    }
}
