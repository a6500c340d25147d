//! The scene registry (filled in by the scenes issue).
