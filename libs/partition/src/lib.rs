//! The process partition: schedule configuration, roles and the stage loops of each module.
