//! Logging through the master's `fmi2CallbackLogger` (FMI 2.0 sections 2.1.5 and 2.2.4).
//!
//! Rules, as in the Modelica Reference FMUs:
//! * the callback is C-variadic and formats with `vsnprintf`, so the layer always passes the
//!   format `"%s"` and the text as the single argument (a `%` in a message is harmless);
//! * interior NUL bytes are replaced by U+FFFD;
//! * messages of status Warning, Discard, Error, Fatal are always sent (fmpy instantiates
//!   with `loggingOn = false`, libcosim shows the last message as the error text);
//! * `fmi2OK` (info/debug) messages are sent only when logging is on and their category
//!   is enabled (`fmi2SetDebugLogging`). A category not declared in the model description
//!   is governed by the logging switch alone.

use std::ffi::{c_int, CString};
use std::fmt;

use crate::description::LogCategory;
use crate::ffi::{Fmi2CallbackLogger, Fmi2ComponentEnvironment, Fmi2Status};

/// A Rust-side message sink for [`Logger::from_fn`].
type RustSink = Box<dyn Fn(Fmi2Status, &str, &str)>;

enum Sink {
    /// The master's callback and its environment pointer.
    Master {
        callback: Fmi2CallbackLogger,
        environment: Fmi2ComponentEnvironment,
    },
    /// A Rust closure (tests, in-process use).
    Rust(RustSink),
    /// Drops everything.
    Silent,
}

/// Safe logging handle to the master's callback, passed to every [`crate::Fmi2Model`] method.
///
/// `info`/`log(Fmi2Status::Ok, ..)` messages are filtered by the logging switch and the
/// category flags; `warning`, `error` and every message of status Warning or worse are
/// always sent. Logging never changes the status an FMI function returns: a model reports
/// failure through its return value.
pub struct Logger {
    sink: Sink,
    instance_name: String,
    instance_name_c: CString,
    logging_on: bool,
    categories: &'static [LogCategory],
    enabled: Vec<bool>,
    calls_index: Option<usize>,
}

impl fmt::Debug for Logger {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sink = match self.sink {
            Sink::Master { .. } => "master callback",
            Sink::Rust(_) => "Rust closure",
            Sink::Silent => "silent",
        };
        f.debug_struct("Logger")
            .field("sink", &sink)
            .field("instance_name", &self.instance_name)
            .field("logging_on", &self.logging_on)
            .field(
                "enabled",
                &self
                    .categories
                    .iter()
                    .zip(&self.enabled)
                    .map(|(c, e)| (c.name.as_str(), *e))
                    .collect::<Vec<_>>(),
            )
            .finish()
    }
}

/// `CString` from text, interior NULs replaced by U+FFFD.
pub(crate) fn to_cstring(text: &str) -> CString {
    match CString::new(text) {
        Ok(c) => c,
        Err(_) => CString::new(text.replace('\0', "\u{FFFD}")).unwrap_or_default(),
    }
}

/// The category used for a message of `status` sent without an explicit category.
pub(crate) fn status_category(status: Fmi2Status) -> &'static str {
    match status {
        Fmi2Status::Ok => "logAll",
        Fmi2Status::Warning => "logStatusWarning",
        Fmi2Status::Discard => "logStatusDiscard",
        Fmi2Status::Error => "logStatusError",
        Fmi2Status::Fatal => "logStatusFatal",
        Fmi2Status::Pending => "logStatusPending",
    }
}

impl Logger {
    fn with_sink(
        sink: Sink,
        instance_name: &str,
        categories: &'static [LogCategory],
        logging_on: bool,
    ) -> Self {
        Logger {
            sink,
            instance_name: instance_name.to_string(),
            instance_name_c: to_cstring(instance_name),
            logging_on,
            categories,
            enabled: vec![true; categories.len()],
            calls_index: categories.iter().position(|c| c.name == "logCalls"),
        }
    }

    /// A logger that forwards to the master's callback (all categories enabled; logging
    /// switched by `logging_on`, the `loggingOn` argument of `fmi2Instantiate`).
    pub(crate) fn master(
        callback: Fmi2CallbackLogger,
        environment: Fmi2ComponentEnvironment,
        instance_name: &str,
        categories: &'static [LogCategory],
        logging_on: bool,
    ) -> Self {
        Self::with_sink(
            Sink::Master {
                callback,
                environment,
            },
            instance_name,
            categories,
            logging_on,
        )
    }

    /// A logger that drops every message (for unit tests of a model).
    pub fn silent(instance_name: &str) -> Self {
        Self::with_sink(Sink::Silent, instance_name, &[], false)
    }

    /// A logger that hands `(status, category, message)` to a Rust closure, with logging on
    /// and every category enabled (for unit tests of a model, or in-process use).
    pub fn from_fn(
        instance_name: &str,
        categories: &'static [LogCategory],
        sink: impl Fn(Fmi2Status, &str, &str) + 'static,
    ) -> Self {
        Self::with_sink(Sink::Rust(Box::new(sink)), instance_name, categories, true)
    }

    /// The instance name given to `fmi2Instantiate`.
    pub fn instance_name(&self) -> &str {
        &self.instance_name
    }

    /// Whether an info message of `category` would be sent now.
    pub fn is_enabled(&self, category: &str) -> bool {
        if !self.logging_on {
            return false;
        }
        match self.categories.iter().position(|c| c.name == category) {
            Some(i) => self.enabled.get(i).copied().unwrap_or(false),
            None => true,
        }
    }

    /// Whether the layer's per-call trace (`logCalls`) is on.
    pub(crate) fn calls_enabled(&self) -> bool {
        self.logging_on
            && self
                .calls_index
                .is_some_and(|i| self.enabled.get(i).copied().unwrap_or(false))
    }

    /// An info message (status `fmi2OK`) in `category`; sent only when enabled.
    pub fn info(&self, category: &str, msg: &str) {
        self.log(Fmi2Status::Ok, category, msg);
    }

    /// A warning (status `fmi2Warning`, category `logStatusWarning`); always sent.
    pub fn warning(&self, msg: &str) {
        self.log(
            Fmi2Status::Warning,
            status_category(Fmi2Status::Warning),
            msg,
        );
    }

    /// An error message (status `fmi2Error`, category `logStatusError`); always sent.
    pub fn error(&self, msg: &str) {
        self.log(Fmi2Status::Error, status_category(Fmi2Status::Error), msg);
    }

    /// A message with explicit status and category. `fmi2OK` messages are filtered by
    /// [`is_enabled`](Self::is_enabled); all others are always sent.
    pub fn log(&self, status: Fmi2Status, category: &str, msg: &str) {
        if status == Fmi2Status::Ok && !self.is_enabled(category) {
            return;
        }
        match &self.sink {
            Sink::Master {
                callback,
                environment,
            } => {
                let category = to_cstring(category);
                let msg = to_cstring(msg);
                // SAFETY: `callback` is the master's non-NULL `fmi2CallbackLogger`, checked at
                // instantiation. All string arguments are valid NUL-terminated strings that
                // outlive the call, the format is the literal "%s" and exactly one `char*`
                // vararg follows it, as `vsnprintf` in the master expects.
                unsafe {
                    callback(
                        *environment,
                        self.instance_name_c.as_ptr(),
                        status as c_int,
                        category.as_ptr(),
                        c"%s".as_ptr(),
                        msg.as_ptr(),
                    );
                }
            }
            Sink::Rust(f) => f(status, category, msg),
            Sink::Silent => {}
        }
    }

    /// `fmi2SetDebugLogging` (FMI 2.0 section 2.1.5): with no categories, `on` applies to
    /// the switch and every category; otherwise the switch is set to `on` and each named
    /// category to `on`. An unknown name is an error naming it, and nothing changes.
    pub(crate) fn set_debug_logging(&mut self, on: bool, names: &[&str]) -> Result<(), String> {
        let mut indices = Vec::with_capacity(names.len());
        for name in names {
            match self.categories.iter().position(|c| c.name == *name) {
                Some(i) => indices.push(i),
                None => {
                    return Err(format!(
                        "unknown log category '{name}' (declared: {})",
                        self.categories
                            .iter()
                            .map(|c| c.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                }
            }
        }
        self.logging_on = on;
        if names.is_empty() {
            self.enabled.iter_mut().for_each(|e| *e = on);
        } else {
            for i in indices {
                self.enabled[i] = on;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, LazyLock, Mutex};

    static CATS: LazyLock<Vec<LogCategory>> = LazyLock::new(|| {
        let mut c = LogCategory::standard();
        c.push(LogCategory::new("logEvents", "events"));
        c
    });

    type Seen = Arc<Mutex<Vec<(Fmi2Status, String, String)>>>;

    fn capture() -> (Logger, Seen) {
        let seen: Seen = Arc::default();
        let s = seen.clone();
        let logger = Logger::from_fn("inst", &CATS, move |st, cat, msg| {
            s.lock().unwrap_or_else(|e| e.into_inner()).push((
                st,
                cat.to_string(),
                msg.to_string(),
            ));
        });
        (logger, seen)
    }

    fn count(seen: &Seen) -> usize {
        seen.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    #[test]
    fn info_filtered_by_switch_and_category_warnings_always() {
        let (mut log, seen) = capture();
        log.info("logEvents", "a");
        assert_eq!(count(&seen), 1);
        log.set_debug_logging(false, &[])
            .unwrap_or_else(|e| panic!("{e}"));
        log.info("logEvents", "b");
        log.info("undeclared", "b");
        assert_eq!(count(&seen), 1);
        log.warning("w");
        log.error("e");
        log.log(Fmi2Status::Discard, "x", "d");
        assert_eq!(count(&seen), 4);
        log.set_debug_logging(true, &["logCalls"])
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(log.calls_enabled());
        assert!(!log.is_enabled("logEvents"));
        assert!(log.is_enabled("undeclared"));
        log.info("logEvents", "c");
        assert_eq!(count(&seen), 4);
    }

    #[test]
    fn unknown_category_is_rejected_and_nothing_changes() {
        let (mut log, _) = capture();
        let err = log
            .set_debug_logging(false, &["logEvents", "nope"])
            .err()
            .unwrap_or_default();
        assert!(err.contains("'nope'"), "{err}");
        assert!(log.is_enabled("logEvents"));
    }

    #[test]
    fn nul_bytes_are_replaced() {
        assert_eq!(to_cstring("a\0b").to_str().ok(), Some("a\u{FFFD}b"));
        assert_eq!(to_cstring("plain").to_str().ok(), Some("plain"));
    }
}
