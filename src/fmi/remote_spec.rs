//! Where a proxy FMU (`talus fmu --remote KEY`) finds its node: `resources/remote.toml`.

use serde::{Deserialize, Serialize};

/// The file in a proxy FMU's resources that makes its instances remote.
pub const REMOTE_FILE: &str = "remote.toml";

/// The longest a proxy FMU waits for its node by default, s: a call (a long step
/// included) without an answer by then is an FMI error.
pub const DEFAULT_TIMEOUT: f64 = 60.0;

/// The node a proxy FMU forwards its calls to.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RemoteSpec {
    /// The node's key (`talus serve --key KEY`).
    pub key: String,
    /// zenoh endpoints to connect to, e.g. `tcp/cluster-node:7447`; none: multicast
    /// scouting finds the node.
    #[serde(default)]
    pub connect: Vec<String>,
    /// Seconds to wait for an answer to any call before it is an FMI error.
    #[serde(default = "default_timeout")]
    pub timeout: f64,
}

fn default_timeout() -> f64 {
    DEFAULT_TIMEOUT
}

impl RemoteSpec {
    /// The spec as `remote.toml` holds it.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a remote spec serialises")
    }

    /// A spec from `remote.toml`'s text, checked.
    pub fn from_toml(text: &str) -> Result<Self, String> {
        let spec: RemoteSpec =
            toml::from_str(text).map_err(|e| format!("{REMOTE_FILE}: {}", e.message()))?;
        spec.checked().map_err(|e| format!("{REMOTE_FILE}: {e}"))
    }

    /// The spec if its key names a node and its timeout is a positive number.
    pub fn checked(self) -> Result<Self, String> {
        if self.key.trim_matches('/').is_empty() {
            return Err("the key is empty".into());
        }
        if !(self.timeout.is_finite() && self.timeout > 0.0) {
            return Err(format!(
                "timeout {} s is not a positive number",
                self.timeout
            ));
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spec_round_trips_and_bad_ones_say_what_is_wrong() {
        let spec = RemoteSpec {
            key: "talus/drum".into(),
            connect: vec!["tcp/10.0.0.5:7447".into()],
            timeout: 12.5,
        };
        assert_eq!(RemoteSpec::from_toml(&spec.to_toml()).unwrap(), spec);
        let defaults = RemoteSpec::from_toml("key = \"talus/x\"").unwrap();
        assert!(defaults.connect.is_empty() && defaults.timeout == DEFAULT_TIMEOUT);
        for (text, words) in [
            ("key = \"/\"", "the key is empty"),
            ("key = \"k\"\ntimeout = 0.0", "not a positive number"),
            ("key = \"k\"\ntimeout = nan", "not a positive number"),
            ("key = \"k\"\nport = 7447", "unknown field `port`"),
            ("connect = []", "missing field `key`"),
        ] {
            let err = RemoteSpec::from_toml(text).unwrap_err();
            assert!(err.starts_with(REMOTE_FILE) && err.contains(words), "{err}");
        }
    }
}
