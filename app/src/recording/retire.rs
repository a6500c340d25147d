//! Configurations that have gone from a stream that goes on (issue #57). The app's live stream,
//! followed by the class's browsers, runs on across a lesson's steps, a new mesh or a reset, and
//! must then show only what runs now. A temporal `Clear` hides what an entity logged before it,
//! but neither its static data (the topology, the rest shape's ghost, the chart lines' names:
//! Rerun cannot clear static data, rerun-io/rerun#11919) nor, in a chart over a time range, its
//! earlier values. Static data shadows the temporal data of the same component at every time and
//! is replaced by the next static write (rerun-io/rerun#5535), so a configuration is retired by
//! logging, as static, an empty value of every component it ever logged — except on the entities
//! that the configurations replacing it log themselves.

use rerun::external::arrow::array::new_empty_array;
use rerun::{EntityPath, RecordingStream, RecordingStreamError, SerializedComponentBatch};
use std::collections::HashMap;

/// Every entity and component a recorder has logged, each with an empty value.
#[derive(Default)]
pub struct Logged {
    empties: HashMap<EntityPath, Vec<SerializedComponentBatch>>,
}

impl Logged {
    /// Logs `archetype` at `path` (static or at the current time) and remembers its components.
    pub fn log<A: ?Sized + rerun::AsComponents>(
        &mut self,
        rec: &RecordingStream,
        path: impl Into<EntityPath>,
        statics: bool,
        archetype: &A,
    ) -> Result<(), RecordingStreamError> {
        let path = path.into();
        let batches = archetype.as_serialized_batches();
        let empties = self.empties.entry(path.clone()).or_default();
        for batch in &batches {
            if !empties.iter().any(|e| e.descriptor == batch.descriptor) {
                let empty = new_empty_array(batch.array.data_type());
                empties.push(SerializedComponentBatch::new(empty, batch.descriptor.clone()));
            }
        }
        rec.log_with_static(path, statics, &batches)
    }

    /// Logs `archetype` at `path` at the current time and remembers its components.
    pub fn at<A: ?Sized + rerun::AsComponents>(
        &mut self,
        rec: &RecordingStream,
        path: impl Into<EntityPath>,
        archetype: &A,
    ) -> Result<(), RecordingStreamError> {
        self.log(rec, path, false, archetype)
    }

    /// Hides, at every time, what was logged here on the entities `replacement` has not logged.
    pub fn retire(&self, rec: &RecordingStream, replacement: &Logged) -> Result<(), RecordingStreamError> {
        for (path, empties) in &self.empties {
            if !replacement.empties.contains_key(path) {
                rec.log_static(path.clone(), empties)?;
            }
        }
        Ok(())
    }
}
