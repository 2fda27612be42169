//! Built-in mechanisms with their references (in progress).
