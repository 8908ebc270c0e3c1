//! IDL 4.2 compiler: preprocess → parse → resolve → validate → emit.
