//! Open-loop command profiles: the CSV read by `safe-capture simulate --commands`.
//!
//! Format: a header line with exactly [`PROFILE_COLUMNS`], then one row per change of
//! command. Row `k` holds from its time `t_s` until the next row's time (zero-order
//! hold); the command applied over the control period starting at `t` is the last row
//! with `t_s ≤ t` (zero before the first row). Forces/torques in the servicer base
//! frame [N, N m], joint torques [N m].
//!
//! The simulator changes its command only at the control steps, so every row's time must
//! be a multiple of the control period (within [`GRID_TOLERANCE_S`]): a row between two
//! steps would silently act from the next one. A profile needs at least one row.

use crate::state::Command;
use nalgebra::Vector3;
use sc_multibody::Vector7;

/// Header of a command profile.
pub const PROFILE_COLUMNS: [&str; 14] = [
    "t_s",
    "f_b_x_n",
    "f_b_y_n",
    "f_b_z_n",
    "tau_b_x_nm",
    "tau_b_y_nm",
    "tau_b_z_nm",
    "tau_m_1_nm",
    "tau_m_2_nm",
    "tau_m_3_nm",
    "tau_m_4_nm",
    "tau_m_5_nm",
    "tau_m_6_nm",
    "tau_m_7_nm",
];

/// How far a row's time may lie from the nearest multiple of the control period [s]:
/// room for the rounding of a time written as `k · period` in decimal (1e-17 s at 0.1 s,
/// 1e-13 s at 1e4 s), far below any physics step (milliseconds). The same tolerance
/// decides which row holds at a control step ([`CommandProfile::at`]).
pub const GRID_TOLERANCE_S: f64 = 1e-9;

/// Why a profile was rejected; every message names the line (and column) at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProfileError {
    #[error("command profile is empty (expected the header `{}`)", PROFILE_COLUMNS.join(","))]
    Empty,
    #[error("line {line}: header column {index} is `{found}`, expected `{expected}`")]
    Header {
        line: usize,
        index: usize,
        found: String,
        expected: String,
    },
    #[error("line {line}: expected {expected} columns, found {found}")]
    Columns {
        line: usize,
        expected: usize,
        found: usize,
    },
    #[error("line {line}, column `{column}`: `{value}` is not a number")]
    NotANumber {
        line: usize,
        column: String,
        value: String,
    },
    #[error("line {line}, column `{column}`: value {value} is not finite")]
    NotFinite {
        line: usize,
        column: String,
        value: f64,
    },
    #[error("line {line}: time {t} s does not increase (previous row at {prev} s)")]
    TimeOrder { line: usize, t: f64, prev: f64 },
    #[error(
        "line {line}, column `t_s`: time {t} s is off the control grid (every row's time must be a multiple of the control period {period} s within {GRID_TOLERANCE_S:e} s)"
    )]
    OffGrid { line: usize, t: f64, period: f64 },
    #[error(
        "line {line}: no row after the header (a profile needs at least one row: its time and command)"
    )]
    NoRows { line: usize },
    #[error("control period {0} s: must be a finite number > 0")]
    Period(f64),
}

/// The header (line `line`) names exactly [`PROFILE_COLUMNS`], in order.
fn check_header(line: usize, header: &str) -> Result<(), ProfileError> {
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    for (i, expected) in PROFILE_COLUMNS.iter().enumerate() {
        let found = names.get(i).copied().unwrap_or("");
        if found != *expected {
            return Err(ProfileError::Header {
                line,
                index: i + 1,
                found: found.into(),
                expected: (*expected).into(),
            });
        }
    }
    if names.len() != PROFILE_COLUMNS.len() {
        return Err(ProfileError::Columns {
            line,
            expected: PROFILE_COLUMNS.len(),
            found: names.len(),
        });
    }
    Ok(())
}

/// The finite numbers of one row (line `line`), in [`PROFILE_COLUMNS`] order.
fn parse_row(line: usize, text: &str) -> Result<[f64; PROFILE_COLUMNS.len()], ProfileError> {
    let cells: Vec<&str> = text.split(',').map(str::trim).collect();
    if cells.len() != PROFILE_COLUMNS.len() {
        return Err(ProfileError::Columns {
            line,
            expected: PROFILE_COLUMNS.len(),
            found: cells.len(),
        });
    }
    let mut v = [0.0; PROFILE_COLUMNS.len()];
    for (k, cell) in cells.iter().enumerate() {
        let x: f64 = cell.parse().map_err(|_| ProfileError::NotANumber {
            line,
            column: PROFILE_COLUMNS[k].into(),
            value: (*cell).into(),
        })?;
        if !x.is_finite() {
            return Err(ProfileError::NotFinite {
                line,
                column: PROFILE_COLUMNS[k].into(),
                value: x,
            });
        }
        v[k] = x;
    }
    Ok(v)
}

/// A parsed, validated command profile.
#[derive(Debug, Clone, PartialEq)]
pub struct CommandProfile {
    rows: Vec<(f64, Command)>,
}

impl CommandProfile {
    /// Parses the CSV text of a profile whose rows lie on the grid of `period_s` [s]
    /// (the scenario's control period).
    pub fn parse(text: &str, period_s: f64) -> Result<Self, ProfileError> {
        if !(period_s.is_finite() && period_s > 0.0) {
            return Err(ProfileError::Period(period_s));
        }
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        let (header_index, header) = lines.next().ok_or(ProfileError::Empty)?;
        check_header(header_index + 1, header)?;
        let mut rows: Vec<(f64, Command)> = Vec::new();
        for (i, line) in lines {
            let line_no = i + 1;
            let v = parse_row(line_no, line)?;
            let nearest = (v[0] / period_s).round() * period_s;
            if (v[0] - nearest).abs() > GRID_TOLERANCE_S {
                return Err(ProfileError::OffGrid {
                    line: line_no,
                    t: v[0],
                    period: period_s,
                });
            }
            if let Some((prev, _)) = rows.last()
                && v[0] <= *prev
            {
                return Err(ProfileError::TimeOrder {
                    line: line_no,
                    t: v[0],
                    prev: *prev,
                });
            }
            let cmd = Command {
                force_b: Vector3::new(v[1], v[2], v[3]),
                torque_b: Vector3::new(v[4], v[5], v[6]),
                tau: Vector7::from_column_slice(&v[7..14]),
            };
            rows.push((v[0], cmd));
        }
        if rows.is_empty() {
            return Err(ProfileError::NoRows {
                line: header_index + 1,
            });
        }
        Ok(Self { rows })
    }

    /// The command that holds at time `t` [s] (zero before the first row).
    pub fn at(&self, t: f64) -> Command {
        let idx = self
            .rows
            .partition_point(|(ti, _)| *ti <= t + GRID_TOLERANCE_S);
        if idx == 0 {
            Command::zero()
        } else {
            self.rows[idx - 1].1
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True if the profile has no rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Writes a profile as CSV text (inverse of [`Self::parse`]).
    pub fn to_csv(rows: &[(f64, Command)]) -> String {
        let mut s = PROFILE_COLUMNS.join(",");
        s.push('\n');
        for (t, c) in rows {
            let vals: Vec<String> = std::iter::once(*t)
                .chain(c.force_b.iter().copied())
                .chain(c.torque_b.iter().copied())
                .chain(c.tau.iter().copied())
                .map(|x| format!("{x}"))
                .collect();
            s.push_str(&vals.join(","));
            s.push('\n');
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default scenario's control period [s].
    const PERIOD: f64 = 0.1;

    /// A row at `t` with zero command.
    fn row(t: &str) -> String {
        format!("{t},0,0,0,0,0,0,0,0,0,0,0,0,0\n")
    }

    fn header() -> String {
        PROFILE_COLUMNS.join(",")
    }

    #[test]
    fn zero_order_hold_lookup() {
        let text = format!(
            "{}\n0,1,0,0,0,0,0,0,0,0,0,0,0,0\n10,2,0,0,0,0,0,0,0,0,0,0,0,0.5\n",
            header()
        );
        let p = CommandProfile::parse(&text, PERIOD).unwrap();
        assert_eq!(p.at(-1.0), Command::zero());
        assert_eq!(p.at(0.0).force_b.x, 1.0);
        assert_eq!(p.at(9.95).force_b.x, 1.0);
        assert_eq!(p.at(10.0).force_b.x, 2.0);
        assert_eq!(p.at(100.0).tau[6], 0.5);
        let again = CommandProfile::parse(&CommandProfile::to_csv(&p.rows), PERIOD).unwrap();
        assert_eq!(again, p);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = CommandProfile::parse(
            &format!("{}\n0,1,0,0,0,0,0,0,0,0,0,0,0,NaN\n", header()),
            PERIOD,
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("line 2") && e.to_string().contains("tau_m_7_nm"),
            "{e}"
        );
        let e = CommandProfile::parse(
            &format!("{}\n0,1,0,x,0,0,0,0,0,0,0,0,0,0\n", header()),
            PERIOD,
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("f_b_z_n") && e.to_string().contains("not a number"),
            "{e}"
        );
        let e = CommandProfile::parse(&format!("{}\n0,1,0\n", header()), PERIOD).unwrap_err();
        assert!(matches!(e, ProfileError::Columns { line: 2, .. }), "{e}");
        let e = CommandProfile::parse("t_s,fx\n", PERIOD).unwrap_err();
        assert!(matches!(e, ProfileError::Header { index: 2, .. }), "{e}");
        let e = CommandProfile::parse(
            &format!(
                "{}\n5,0,0,0,0,0,0,0,0,0,0,0,0,0\n5,0,0,0,0,0,0,0,0,0,0,0,0,0\n",
                header()
            ),
            PERIOD,
        )
        .unwrap_err();
        assert!(matches!(e, ProfileError::TimeOrder { line: 3, .. }), "{e}");
        assert_eq!(
            CommandProfile::parse("", PERIOD).unwrap_err(),
            ProfileError::Empty
        );
    }

    #[test]
    fn rows_off_the_control_grid_are_refused() {
        // 0.15 s lies between the steps at 0.1 and 0.2 s
        let text = format!("{}\n{}{}", header(), row("0"), row("0.15"));
        let e = CommandProfile::parse(&text, PERIOD).unwrap_err();
        assert!(
            matches!(e, ProfileError::OffGrid { line: 3, t, .. } if t == 0.15),
            "{e}"
        );
        let msg = e.to_string();
        assert!(
            msg.contains("line 3")
                && msg.contains("0.15")
                && msg.contains("multiple of the control period 0.1 s"),
            "{msg}"
        );
        // just beyond the tolerance is off, within it on (a time written as k · period)
        let off = format!("{}", 0.3 + 2.0 * GRID_TOLERANCE_S);
        let e = CommandProfile::parse(&format!("{}\n{}", header(), row(&off)), PERIOD).unwrap_err();
        assert!(matches!(e, ProfileError::OffGrid { line: 2, .. }), "{e}");
        let on = format!("{:?}", 3.0 * PERIOD); // 0.30000000000000004
        let p = CommandProfile::parse(
            &format!("{}\n{}{}", header(), row("-0.1"), row(&on)),
            PERIOD,
        )
        .unwrap();
        assert_eq!(p.len(), 2);
        // the grid is the period's: 0.15 s is on a 0.05 s grid
        assert!(CommandProfile::parse(&text, 0.05).is_ok());
    }

    #[test]
    fn a_profile_without_rows_is_refused() {
        let e = CommandProfile::parse(&format!("{}\n", header()), PERIOD).unwrap_err();
        assert_eq!(e, ProfileError::NoRows { line: 1 });
        assert!(e.to_string().contains("line 1") && e.to_string().contains("at least one row"));
        // comments and blank lines are no rows; the header's own line is named
        let e = CommandProfile::parse(
            &format!("# made by hand\n\n{}\n# nothing\n", header()),
            PERIOD,
        )
        .unwrap_err();
        assert_eq!(e, ProfileError::NoRows { line: 3 });
    }

    #[test]
    fn a_bad_period_is_an_error_not_a_panic() {
        for period in [0.0, -0.1, f64::NAN, f64::INFINITY] {
            let e =
                CommandProfile::parse(&format!("{}\n{}", header(), row("0")), period).unwrap_err();
            assert!(matches!(e, ProfileError::Period(_)), "{period}: {e}");
        }
    }
}
