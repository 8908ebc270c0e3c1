//! The `shapes` demo apart from its window: command line, DDS entities and published shapes ([`session`]),
//! the line output ([`batch`]) and the end-of-run summary ([`tally`]). The terminal UI (`crate::shapes_ui`)
//! drives the same [`session::Session`].

pub mod args;
pub mod batch;
pub mod origin;
pub mod session;
pub mod tally;

use dds_runtime::prelude::DdsResult;

use args::ShapesArgs;
use session::{Session, SessionConfig};

/// A session with the readers and publications the command line asks for.
pub fn session_from_args(a: &ShapesArgs) -> DdsResult<Session> {
    let mut session = Session::new(SessionConfig {
        domain: a.domain,
        xcdr2: a.xcdr == 2,
        rate_hz: a.rate,
    });
    // Reader first, so that the first samples find it.
    if a.subscribes() {
        session.subscribe(&a.topic)?;
    }
    for (i, c) in a.publish_colors().iter().enumerate() {
        session.publish(&a.topic, c, i)?;
    }
    Ok(session)
}
