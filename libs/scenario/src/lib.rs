//! Scenario configuration: the mission as data.
