//! The properties Cyclone DDS announces for a participant in SPDP (`PID_PROPERTY_LIST`) and its `cyclonedds ps`
//! reads: `__Hostname`, `__Pid` and `__ProcessName`.

/// Property names (Cyclone DDS's `DDS_BUILTIN_TOPIC_PARTICIPANT_PROPERTY_*`).
pub(crate) const HOSTNAME: &str = "__Hostname";
/// Process id, decimal.
pub(crate) const PID: &str = "__Pid";
/// Executable name (without its directory).
pub(crate) const PROCESS_NAME: &str = "__ProcessName";

/// `(name, value)` of the three properties for this process.
pub(crate) fn properties() -> Vec<(String, String)> {
    vec![
        (HOSTNAME.to_owned(), hostname()),
        (PID.to_owned(), std::process::id().to_string()),
        (PROCESS_NAME.to_owned(), process_name()),
    ]
}

fn process_name() -> String {
    std::env::current_exe()
        .ok()
        .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .or_else(|| {
            std::env::args_os().next().and_then(|a| {
                std::path::Path::new(&a)
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
            })
        })
        .unwrap_or_default()
}

#[cfg(unix)]
fn hostname() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is valid for its length; gethostname NUL-terminates within it on success.
    let rc = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if rc != 0 {
        return String::new();
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    String::from_utf8_lossy(&buf[..end]).into_owned()
}

#[cfg(not(unix))]
fn hostname() -> String {
    std::env::var("COMPUTERNAME").unwrap_or_default()
}

#[cfg(test)]
mod tests {
    #[test]
    fn announces_host_pid_and_program() {
        let p = super::properties();
        assert_eq!(p[1], ("__Pid".to_owned(), std::process::id().to_string()));
        assert!(!p[0].1.is_empty(), "host name");
        assert!(!p[2].1.is_empty(), "program name");
    }
}
