//! The 25 shape type variants of the OMG XTypes interoperability suite (omg-dds/dds-xtypes), written as our
//! own Rust types from the suite's description: Shape1 (color, x, y, shapesize), Shape2 (+ angle at the end),
//! Shape3 (+ z in the middle), Shape4 (members reordered), Shape5 (Shape1 as a base + angle); each in five
//! flavours: no annotation (the XTypes 1.3 default, @appendable), @final, @appendable, @mutable, and @mutable
//! with explicit ids. Variant `k` (1-based) is shape `(k - 1) % 5 + 1` of flavour `(k - 1) / 5`, the suite's
//! numbering.
#![allow(dead_code)]

use dds_runtime::DdsType;

/// What every variant holds, as one value: `z` and `angle` are `None` in a variant without them.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Fields {
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub z: Option<i32>,
    pub angle: Option<f32>,
}

impl Fields {
    /// The sample writer `k` writes: key `W<k>`, values derived from `k`.
    pub(crate) fn of_writer(k: usize) -> Fields {
        let k32 = k as i32;
        Fields {
            color: format!("W{k}"),
            x: k32,
            y: 2 * k32,
            shapesize: 30,
            z: Some(3 * k32),
            angle: Some(5.0 * k as f32),
        }
    }

    /// What a reader with (`has_z`, `has_angle`) shows of a sample written as `self` by a writer with
    /// (`w_z`, `w_angle`): shared members as written, its own extra members at their defaults.
    pub(crate) fn as_read(&self, w: (bool, bool), r: (bool, bool)) -> Fields {
        Fields {
            z: r.0.then(|| if w.0 { self.z.unwrap_or(0) } else { 0 }),
            angle: r
                .1
                .then(|| if w.1 { self.angle.unwrap_or(0.0) } else { 0.0 }),
            ..self.clone()
        }
    }
}

/// A shape variant.
pub(crate) trait Variant:
    dds_runtime::cdr::DdsType + dds_runtime::xtypes::XTypesType + Send + Sync + 'static
{
    /// The suite's number, 1..=25.
    const INDEX: usize;
    /// Whether it has `z` and `angle`.
    const HAS: (bool, bool);
    /// The variant holding `f` (members it lacks dropped).
    fn from_fields(f: &Fields) -> Self;
    /// Its members as [`Fields`].
    fn fields(&self) -> Fields;
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape1Default")]
pub(crate) struct Shape1Default {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
}

impl Variant for Shape1Default {
    const INDEX: usize = 1;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape1Default {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape2Default")]
pub(crate) struct Shape2Default {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub angle: f32,
}

impl Variant for Shape2Default {
    const INDEX: usize = 2;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape2Default {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: Some(self.angle),
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape3Default")]
pub(crate) struct Shape3Default {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub z: i32,
    pub shapesize: i32,
}

impl Variant for Shape3Default {
    const INDEX: usize = 3;
    const HAS: (bool, bool) = (true, false);
    fn from_fields(f: &Fields) -> Self {
        Shape3Default {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            z: f.z.unwrap_or(0),
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: Some(self.z),
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape4Default")]
pub(crate) struct Shape4Default {
    #[dds(key, bound = 32)]
    pub color: String,
    pub shapesize: i32,
    pub x: i32,
    pub y: i32,
}

impl Variant for Shape4Default {
    const INDEX: usize = 4;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape4Default {
            color: f.color.clone(),
            shapesize: f.shapesize,
            x: f.x,
            y: f.y,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape5Default")]
pub(crate) struct Shape5Default {
    #[dds(base)]
    pub base: Shape1Default,
    pub angle: f32,
}

impl Variant for Shape5Default {
    const INDEX: usize = 5;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape5Default {
            base: Shape1Default::from_fields(f),
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            angle: Some(self.angle),
            ..self.base.fields()
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, name = "Shape1Final")]
pub(crate) struct Shape1Final {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
}

impl Variant for Shape1Final {
    const INDEX: usize = 6;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape1Final {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, name = "Shape2Final")]
pub(crate) struct Shape2Final {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub angle: f32,
}

impl Variant for Shape2Final {
    const INDEX: usize = 7;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape2Final {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: Some(self.angle),
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, name = "Shape3Final")]
pub(crate) struct Shape3Final {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub z: i32,
    pub shapesize: i32,
}

impl Variant for Shape3Final {
    const INDEX: usize = 8;
    const HAS: (bool, bool) = (true, false);
    fn from_fields(f: &Fields) -> Self {
        Shape3Final {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            z: f.z.unwrap_or(0),
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: Some(self.z),
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, name = "Shape4Final")]
pub(crate) struct Shape4Final {
    #[dds(key, bound = 32)]
    pub color: String,
    pub shapesize: i32,
    pub x: i32,
    pub y: i32,
}

impl Variant for Shape4Final {
    const INDEX: usize = 9;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape4Final {
            color: f.color.clone(),
            shapesize: f.shapesize,
            x: f.x,
            y: f.y,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(final, name = "Shape5Final")]
pub(crate) struct Shape5Final {
    #[dds(base)]
    pub base: Shape1Final,
    pub angle: f32,
}

impl Variant for Shape5Final {
    const INDEX: usize = 10;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape5Final {
            base: Shape1Final::from_fields(f),
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            angle: Some(self.angle),
            ..self.base.fields()
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape1Extensible")]
pub(crate) struct Shape1Extensible {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
}

impl Variant for Shape1Extensible {
    const INDEX: usize = 11;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape1Extensible {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape2Extensible")]
pub(crate) struct Shape2Extensible {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub angle: f32,
}

impl Variant for Shape2Extensible {
    const INDEX: usize = 12;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape2Extensible {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: Some(self.angle),
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape3Extensible")]
pub(crate) struct Shape3Extensible {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub z: i32,
    pub shapesize: i32,
}

impl Variant for Shape3Extensible {
    const INDEX: usize = 13;
    const HAS: (bool, bool) = (true, false);
    fn from_fields(f: &Fields) -> Self {
        Shape3Extensible {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            z: f.z.unwrap_or(0),
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: Some(self.z),
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape4Extensible")]
pub(crate) struct Shape4Extensible {
    #[dds(key, bound = 32)]
    pub color: String,
    pub shapesize: i32,
    pub x: i32,
    pub y: i32,
}

impl Variant for Shape4Extensible {
    const INDEX: usize = 14;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape4Extensible {
            color: f.color.clone(),
            shapesize: f.shapesize,
            x: f.x,
            y: f.y,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(appendable, name = "Shape5Extensible")]
pub(crate) struct Shape5Extensible {
    #[dds(base)]
    pub base: Shape1Extensible,
    pub angle: f32,
}

impl Variant for Shape5Extensible {
    const INDEX: usize = 15;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape5Extensible {
            base: Shape1Extensible::from_fields(f),
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            angle: Some(self.angle),
            ..self.base.fields()
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape1Mutable")]
pub(crate) struct Shape1Mutable {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
}

impl Variant for Shape1Mutable {
    const INDEX: usize = 16;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape1Mutable {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape2Mutable")]
pub(crate) struct Shape2Mutable {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub shapesize: i32,
    pub angle: f32,
}

impl Variant for Shape2Mutable {
    const INDEX: usize = 17;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape2Mutable {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: Some(self.angle),
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape3Mutable")]
pub(crate) struct Shape3Mutable {
    #[dds(key, bound = 32)]
    pub color: String,
    pub x: i32,
    pub y: i32,
    pub z: i32,
    pub shapesize: i32,
}

impl Variant for Shape3Mutable {
    const INDEX: usize = 18;
    const HAS: (bool, bool) = (true, false);
    fn from_fields(f: &Fields) -> Self {
        Shape3Mutable {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            z: f.z.unwrap_or(0),
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: Some(self.z),
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape4Mutable")]
pub(crate) struct Shape4Mutable {
    #[dds(key, bound = 32)]
    pub color: String,
    pub shapesize: i32,
    pub x: i32,
    pub y: i32,
}

impl Variant for Shape4Mutable {
    const INDEX: usize = 19;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape4Mutable {
            color: f.color.clone(),
            shapesize: f.shapesize,
            x: f.x,
            y: f.y,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape5Mutable")]
pub(crate) struct Shape5Mutable {
    #[dds(base)]
    pub base: Shape1Mutable,
    pub angle: f32,
}

impl Variant for Shape5Mutable {
    const INDEX: usize = 20;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape5Mutable {
            base: Shape1Mutable::from_fields(f),
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            angle: Some(self.angle),
            ..self.base.fields()
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape1MutableExplicitID")]
pub(crate) struct Shape1MutableExplicitID {
    #[dds(key, bound = 32, id = 10)]
    pub color: String,
    #[dds(id = 20)]
    pub x: i32,
    pub y: i32,
    #[dds(id = 30)]
    pub shapesize: i32,
}

impl Variant for Shape1MutableExplicitID {
    const INDEX: usize = 21;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape1MutableExplicitID {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape2MutableExplicitID")]
pub(crate) struct Shape2MutableExplicitID {
    #[dds(key, bound = 32, id = 10)]
    pub color: String,
    #[dds(id = 20)]
    pub x: i32,
    pub y: i32,
    #[dds(id = 30)]
    pub shapesize: i32,
    #[dds(id = 40)]
    pub angle: f32,
}

impl Variant for Shape2MutableExplicitID {
    const INDEX: usize = 22;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape2MutableExplicitID {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            shapesize: f.shapesize,
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: Some(self.angle),
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape3MutableExplicitID")]
pub(crate) struct Shape3MutableExplicitID {
    #[dds(key, bound = 32, id = 10)]
    pub color: String,
    #[dds(id = 20)]
    pub x: i32,
    pub y: i32,
    #[dds(id = 15)]
    pub z: i32,
    #[dds(id = 30)]
    pub shapesize: i32,
}

impl Variant for Shape3MutableExplicitID {
    const INDEX: usize = 23;
    const HAS: (bool, bool) = (true, false);
    fn from_fields(f: &Fields) -> Self {
        Shape3MutableExplicitID {
            color: f.color.clone(),
            x: f.x,
            y: f.y,
            z: f.z.unwrap_or(0),
            shapesize: f.shapesize,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: Some(self.z),
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape4MutableExplicitID")]
pub(crate) struct Shape4MutableExplicitID {
    #[dds(key, bound = 32, id = 10)]
    pub color: String,
    #[dds(id = 30)]
    pub shapesize: i32,
    #[dds(id = 20)]
    pub x: i32,
    pub y: i32,
}

impl Variant for Shape4MutableExplicitID {
    const INDEX: usize = 24;
    const HAS: (bool, bool) = (false, false);
    fn from_fields(f: &Fields) -> Self {
        Shape4MutableExplicitID {
            color: f.color.clone(),
            shapesize: f.shapesize,
            x: f.x,
            y: f.y,
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            color: self.color.clone(),
            x: self.x,
            y: self.y,
            shapesize: self.shapesize,
            z: None,
            angle: None,
        }
    }
}

#[derive(DdsType, Debug, Clone, PartialEq)]
#[dds(mutable, name = "Shape5MutableExplicitID")]
pub(crate) struct Shape5MutableExplicitID {
    #[dds(base)]
    pub base: Shape1MutableExplicitID,
    #[dds(id = 40)]
    pub angle: f32,
}

impl Variant for Shape5MutableExplicitID {
    const INDEX: usize = 25;
    const HAS: (bool, bool) = (false, true);
    fn from_fields(f: &Fields) -> Self {
        Shape5MutableExplicitID {
            base: Shape1MutableExplicitID::from_fields(f),
            angle: f.angle.unwrap_or(0.0),
        }
    }
    fn fields(&self) -> Fields {
        Fields {
            angle: Some(self.angle),
            ..self.base.fields()
        }
    }
}

/// Calls `$m!(T)` for each of the 25 variants, in the suite's order.
macro_rules! for_each_variant {
    ($m:ident) => {
        $m!(Shape1Default);
        $m!(Shape2Default);
        $m!(Shape3Default);
        $m!(Shape4Default);
        $m!(Shape5Default);
        $m!(Shape1Final);
        $m!(Shape2Final);
        $m!(Shape3Final);
        $m!(Shape4Final);
        $m!(Shape5Final);
        $m!(Shape1Extensible);
        $m!(Shape2Extensible);
        $m!(Shape3Extensible);
        $m!(Shape4Extensible);
        $m!(Shape5Extensible);
        $m!(Shape1Mutable);
        $m!(Shape2Mutable);
        $m!(Shape3Mutable);
        $m!(Shape4Mutable);
        $m!(Shape5Mutable);
        $m!(Shape1MutableExplicitID);
        $m!(Shape2MutableExplicitID);
        $m!(Shape3MutableExplicitID);
        $m!(Shape4MutableExplicitID);
        $m!(Shape5MutableExplicitID);
    };
}

mod erased;
mod matrix;
pub(crate) use erased::*;
pub(crate) use matrix::*;
