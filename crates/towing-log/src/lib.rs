//! MCAP logging shared by both towing FMUs (docs/logging.md).
//!
//! * [`topics`]: the topic contract: topic and schema names, the message structs (the
//!   analyzer deserializes with the same types) and the Foxglove well-known types as serde
//!   structs.
//! * [`writer`]: [`LogWriter`], one MCAP file of JSON messages on simulated time (zstd
//!   chunks closed every [`LogOptions::flush_interval`] of simulated time), and
//!   [`SharedLog`], the handle an FMU model keeps (writing on a thread of its own).
//! * [`scene`]: builders of the Foxglove messages from NED quantities (ENU frame `world`).
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod scene;
pub mod topics;
pub mod writer;

pub use topics::TopicMessage;
pub use writer::{
    schema_json, time_ns, Batch, LogError, LogOptions, LogWriter, RunInfo, SharedLog,
};
