//! Who and when: this machine's host name, the tags that make temporary names unique
//! among the nodes sharing a project folder, and the wall clock.

use std::time::{SystemTime, UNIX_EPOCH};

/// Seconds since the Unix epoch.
pub fn now_unix() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// This machine's host name (for names that must be unique across the nodes sharing a
/// project folder).
pub fn host_name() -> String {
    let mut buf = [0u8; 256];
    let ok = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) } == 0;
    let n = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    let h = String::from_utf8_lossy(&buf[..n]).to_string();
    if ok && !h.is_empty() {
        h.replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_")
    } else {
        "host".into()
    }
}

/// A suffix unique to this process among all nodes: `HOST-PID`.
pub fn process_tag() -> String {
    format!("{}-{}", host_name(), std::process::id())
}

/// The name of this attempt in temporary paths: `slurmJOBID` inside a Slurm job, else
/// `HOST-PID`.
pub fn attempt_tag() -> String {
    match std::env::var("SLURM_JOB_ID") {
        Ok(j) if !j.is_empty() && j.bytes().all(|b| b.is_ascii_digit()) => format!("slurm{j}"),
        _ => process_tag(),
    }
}
