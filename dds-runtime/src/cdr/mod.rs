//! XCDR1/XCDR2 serialization (XTypes 1.3 §7.4).
