//! The suite's compatibility matrix and the pairs where we (and Cyclone DDS 11) disagree with it.

/// The suite's compatibility matrix (its spreadsheet gives the upper triangle; the relation is symmetric for
/// these types): row = writer variant, column = reader variant, `+` compatible, `-` not.
pub(crate) const MATRIX: [&str; 25] = [
    "++--+-----++--+----------",
    "++--+-----++--+----------",
    "--+---------+------------",
    "---+---------+-----------",
    "++--+-----++--+----------",
    "-----+-------------------",
    "------+------------------",
    "-------+-----------------",
    "--------+----------------",
    "---------+---------------",
    "++--+-----++--+----------",
    "++--+-----++--+----------",
    "--+---------+------------",
    "---+---------+-----------",
    "++--+-----++--+----------",
    "---------------+---+-----",
    "----------------+--+-----",
    "-----------------+-------",
    "------------------+------",
    "---------------++--+-----",
    "--------------------+++++",
    "--------------------+++++",
    "--------------------+++++",
    "--------------------+++++",
    "--------------------+++++",
];

/// (writer, reader) pairs where we (and Cyclone DDS 11, whose rules we follow) disagree with the matrix.
pub(crate) const DISAGREE: &[(usize, usize, &str)] = &[
    (7, 10, "Shape2Final and Shape5Final have the same members once Shape5's base is flattened \
             (XTypes 1.3 §7.2.2.4.5, as Cyclone expands bases); the matrix keeps inheritance apart for @final only"),
    (10, 7, "the same pair, the other way"),
    (16, 17, "Shape1Mutable and Shape2Mutable pair every id with the same name; the matrix marks them \
              incompatible yet Shape1Mutable/Shape5Mutable compatible, and Shape2Mutable and Shape5Mutable have \
              the same ids and names"),
    (17, 16, "the same pair, the other way"),
];

/// Whether the matrix says writer `w` and reader `r` (1-based) match.
pub(crate) fn matrix(w: usize, r: usize) -> bool {
    MATRIX[w - 1].as_bytes()[r - 1] == b'+'
}

/// What we expect: the matrix, but for the listed disagreements.
pub(crate) fn expected(w: usize, r: usize) -> bool {
    matrix(w, r) != DISAGREE.iter().any(|(a, b, _)| (*a, *b) == (w, r))
}
