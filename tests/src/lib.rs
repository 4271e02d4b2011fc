//! Scenario-based and property tests live in `tests/tests/`.
