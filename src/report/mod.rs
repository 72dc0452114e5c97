//! Reports: error against run time.
