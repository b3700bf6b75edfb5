//! The station file that connects to an emulator: the emulated station's file with its
//! drivers pointed at the emulator's links and without the faults (the emulator plays them).

/// Where the emulator serves a device.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Served {
    /// A TCP address.
    Tcp(String),
    /// A pseudo-terminal's device path.
    Pty(String),
}

fn driver(served: &Served) -> serde_json::Value {
    match served {
        Served::Tcp(a) => serde_json::json!({ "tcp": { "address": a, "timeout": "2 s" } }),
        Served::Pty(p) => serde_json::json!({ "serial": { "port": p, "timeout": "2 s" } }),
    }
}

/// The YAML of the connecting station, from the emulated station file's text.
pub fn connecting_station(yaml: &str, table: &Served, imu: &Served) -> Result<String, String> {
    let mut v: serde_json::Value =
        serde_saphyr::from_str(yaml).map_err(|e| format!("cannot read the station: {e}"))?;
    let name = v["name"].as_str().unwrap_or("station").to_string();
    v["name"] = format!("{name} (emulated)").into();
    v["table"]["driver"] = driver(table);
    v["imu"]["driver"] = driver(imu);
    v["faults"] = serde_json::json!([]);
    let text = serde_saphyr::to_string(&v).map_err(|e| format!("cannot write the station: {e}"))?;
    Ok(format!(
        "# Connects to a `ratecal emulate` session; written by ratecal emulate.\n{text}"
    ))
}
