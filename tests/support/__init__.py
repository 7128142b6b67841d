"""Support code shared by tests (helpers, not tests)."""
