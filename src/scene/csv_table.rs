//! The CSV tables a scene reads (particle poses, a coupled code's cells): a header
//! naming the columns, so their order is free, then one record per line; blank lines
//! and `#` lines are skipped. Errors start with the line number and name the column.

use crate::Real;

/// A parsed table: its column names and its records with their line numbers.
pub(super) struct CsvTable<'a> {
    names: Vec<&'a str>,
    header_line: usize,
    rows: Vec<(usize, Vec<&'a str>)>,
}

impl<'a> CsvTable<'a> {
    /// The table of `text`; `expected` names the header in the error for an empty
    /// file.
    pub(super) fn parse(text: &'a str, expected: &str) -> Result<Self, String> {
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
            .map(|(n, l)| (n + 1, l.split(',').map(str::trim).collect::<Vec<_>>()));
        let Some((header_line, names)) = lines.next() else {
            return Err(format!(
                "1: the file is empty (expected a header {expected})"
            ));
        };
        Ok(CsvTable {
            names,
            header_line,
            rows: lines.collect(),
        })
    }

    /// The index of the column `name`, if the header has it.
    pub(super) fn column(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| *n == name)
    }

    /// The index of the column `name`, which the header must have.
    pub(super) fn require(&self, name: &str) -> Result<usize, String> {
        self.column(name)
            .ok_or_else(|| format!("{}: the header has no column '{name}'", self.header_line))
    }

    /// The line of the header.
    pub(super) fn header_line(&self) -> usize {
        self.header_line
    }

    /// The records: each with its line number and a reader of its finite numbers
    /// by column.
    pub(super) fn records(&self) -> impl Iterator<Item = Record<'_>> {
        self.rows.iter().map(|(line, fields)| Record {
            line: *line,
            fields,
            names: &self.names,
        })
    }
}

/// One line of a [`CsvTable`].
pub(super) struct Record<'t> {
    /// The line number in the file (from 1).
    pub line: usize,
    fields: &'t [&'t str],
    names: &'t [&'t str],
}

impl Record<'_> {
    /// The finite number in column `c`.
    pub(super) fn value(&self, c: usize) -> Result<Real, String> {
        let (line, name) = (self.line, self.names[c]);
        let f = self
            .fields
            .get(c)
            .ok_or_else(|| format!("{line}: column '{name}' is missing"))?;
        let v: Real = f
            .parse()
            .map_err(|_| format!("{line}: column '{name}': '{f}' is not a number"))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{line}: column '{name}' is not finite"))
        }
    }
}
