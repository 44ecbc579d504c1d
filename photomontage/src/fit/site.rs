//! Site glue (being written).
