//! Typed access to the keys of a model's TOML file: each error names the file and the
//! dotted key (`table.key`) with what is wrong, so a user finds the line to fix.

use crate::error::{ModelsError, Result};

/// The keys of one file (`file`, as the user named it, for messages).
pub(crate) struct Keys<'a> {
    /// The file, for messages.
    pub(crate) file: &'a str,
}

impl Keys<'_> {
    /// The error for `key`: `message` says what is wrong.
    pub(crate) fn key(&self, key: &str, message: impl Into<String>) -> ModelsError {
        ModelsError::Key {
            file: self.file.to_string(),
            key: key.to_string(),
            message: message.into(),
        }
    }

    /// `table.key` (the key quoted when it is not a bare TOML key); `key` alone at the top.
    pub(crate) fn path(table: &str, key: &str) -> String {
        if table.is_empty() {
            key.to_string()
        } else if key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            format!("{table}.{key}")
        } else {
            format!("{table}.{key:?}")
        }
    }

    /// Refuses a key of `t` not in `allowed`, listing the known ones.
    pub(crate) fn known(&self, t: &toml::Table, table: &str, allowed: &[&str]) -> Result<()> {
        match t.keys().find(|k| !allowed.contains(&k.as_str())) {
            Some(k) => Err(self.key(
                &Self::path(table, k),
                format!("unknown key (known here: {})", allowed.join(", ")),
            )),
            None => Ok(()),
        }
    }

    /// The value of `key`; missing is an error.
    pub(crate) fn get<'t>(
        &self,
        t: &'t toml::Table,
        table: &str,
        key: &str,
    ) -> Result<&'t toml::Value> {
        t.get(key)
            .ok_or_else(|| self.key(&Self::path(table, key), "missing"))
    }

    /// The table under `key`.
    pub(crate) fn table<'t>(
        &self,
        t: &'t toml::Table,
        table: &str,
        key: &str,
    ) -> Result<&'t toml::Table> {
        self.get(t, table, key)?
            .as_table()
            .ok_or_else(|| self.key(&Self::path(table, key), "must be a table (`[...]`)"))
    }

    /// `v` as a finite number (integers accepted); `path` names it in errors.
    pub(crate) fn as_number(&self, v: &toml::Value, path: &str) -> Result<f64> {
        let x = v
            .as_float()
            .or_else(|| v.as_integer().map(|i| i as f64))
            .ok_or_else(|| self.key(path, format!("must be a number, found {}", v.type_str())))?;
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.key(path, format!("{x} is not finite")))
        }
    }

    /// The finite number under `key`.
    pub(crate) fn number(&self, t: &toml::Table, table: &str, key: &str) -> Result<f64> {
        self.as_number(self.get(t, table, key)?, &Self::path(table, key))
    }

    /// The number under `key`, which must be above zero.
    pub(crate) fn positive(&self, t: &toml::Table, table: &str, key: &str) -> Result<f64> {
        let x = self.number(t, table, key)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.key(
                &Self::path(table, key),
                format!("{x} must be positive (SI units)"),
            ))
        }
    }

    /// The number under `key`, which must not be below zero.
    pub(crate) fn non_negative(&self, t: &toml::Table, table: &str, key: &str) -> Result<f64> {
        let x = self.number(t, table, key)?;
        if x >= 0.0 {
            Ok(x)
        } else {
            Err(self.key(&Self::path(table, key), format!("{x} must not be negative")))
        }
    }

    /// The string under `key`.
    pub(crate) fn string(&self, t: &toml::Table, table: &str, key: &str) -> Result<String> {
        let v = self.get(t, table, key)?;
        v.as_str().map(str::to_string).ok_or_else(|| {
            self.key(
                &Self::path(table, key),
                format!("must be a string, found {}", v.type_str()),
            )
        })
    }
}
