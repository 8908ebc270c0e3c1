//! Stable diagnostic codes. A code is never reused for another meaning.

macro_rules! codes {
    ($($name:ident = $code:literal : $desc:literal,)*) => {
        /// What a diagnostic is about; each has a stable code such as `idlc::E0201`.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Code { $(#[doc = $desc] $name,)* }
        impl Code {
            /// The code as shown, e.g. `idlc::E0201`.
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$name => concat!("idlc::", $code),)* }
            }
            /// One line saying what the code means.
            pub fn description(self) -> &'static str {
                match self { $(Code::$name => $desc,)* }
            }
            /// Every code, in numbering order.
            pub const ALL: &'static [Code] = &[$(Code::$name,)*];
        }
    };
}

codes! {
    // Preprocessor: E00xx
    Io = "E0001": "a file could not be read",
    IncludeNotFound = "E0002": "an #include names a file that is not on the include path",
    IncludeDepth = "E0003": "#include nesting is too deep (usually an include cycle)",
    ErrorDirective = "E0004": "#error directive",
    BadDirective = "E0005": "unknown or malformed preprocessor directive",
    Conditional = "E0006": "unbalanced #if/#else/#endif",
    PpExpr = "E0007": "invalid #if expression",
    Macro = "E0008": "invalid macro definition or invocation",
    Unterminated = "E0009": "unterminated comment or literal",
    Limit = "E0010": "input exceeds a resource limit (nesting, size)",
    // Syntax: E01xx
    Syntax = "E0101": "syntax error",
    BadLiteral = "E0102": "invalid literal",
    KeywordIdent = "E0103": "identifier collides with a keyword",
    // Names: E02xx
    Unresolved = "E0201": "name not found",
    Ambiguous = "E0202": "name is ambiguous",
    Duplicate = "E0203": "name declared twice in one scope",
    CaseCollision = "E0204": "names differ only in case",
    NotAType = "E0205": "name does not denote the kind of thing needed here",
    IncompleteForward = "E0206": "forward declaration never defined",
    InfiniteType = "E0207": "type contains itself without indirection",
    // Constants: E03xx
    Overflow = "E0301": "constant value out of range of its type",
    ConstType = "E0302": "constant expression has the wrong type",
    DivZero = "E0303": "division by zero in a constant expression",
    BadBound = "E0304": "array size or bound must be a positive integer",
    // Types: E04xx
    DuplicateLabel = "E0401": "duplicate union case label",
    SeveralDefaults = "E0402": "several default labels in one union",
    LabelType = "E0403": "union case label does not match the discriminator type",
    BadDiscriminator = "E0404": "type not allowed as a union discriminator",
    KeyOptional = "E0405": "key member declared optional",
    DerivedKey = "E0406": "derived struct adds key members",
    DuplicateId = "E0407": "two members have the same member id",
    AnnotationParam = "E0408": "invalid annotation parameter",
    BadBase = "E0409": "invalid base type",
    BitBound = "E0410": "bit bound or bit position out of range",
    DuplicateValue = "E0411": "two enumerators have the same value",
    AnnotationPlace = "E0412": "annotation not allowed here",
    DuplicateMember = "E0413": "two members have the same name",
    BadMemberType = "E0414": "type not allowed for this member",
    UnreachableDefault = "E0415": "union default label can never be selected",
    ExtensibilityMismatch = "E0416": "derived struct's extensibility differs from its base's",
    // Warnings
    PragmaIgnored = "W0001": "unknown #pragma ignored",
    WarningDirective = "W0002": "#warning directive",
    NotEmitted = "W0101": "declaration parsed but no Rust is emitted for it",
    LegacyAnnotation = "W0102": "legacy comment annotation",
    UnknownAnnotation = "W0103": "unknown annotation ignored",
    IgnoredAnnotation = "W0104": "annotation has no effect here",
    Renamed = "W0105": "Rust name changed to avoid a collision",
    AnnotationCase = "W0106": "built-in annotation name not in lower case",
    Extension = "W0107": "vendor extension to IDL 4.2 accepted",
}
