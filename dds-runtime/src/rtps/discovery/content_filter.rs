//! PID_CONTENT_FILTER_PROPERTY (RTPS 2.5 §9.6.3.1): the content filter a reader announces in SEDP so that
//! writers can filter for it, and the filter signature of §9.6.4.1 that PID_CONTENT_FILTER_INFO refers to.
//!
//! Wire form (CDR in the parameter list's byte order): `string<256>` content-filtered topic name,
//! `string<256>` related topic name, `string<256>` filter class name, `string` filter expression,
//! `sequence<string>` expression parameters.

use md5::{Digest, Md5};

use crate::rtps::messages::parameter::{pid, put_string, ParameterWriter};
use crate::rtps::messages::{Cursor, WireError};

/// Longest name (topic, related topic, class) accepted, as the spec bounds them.
const MAX_NAME: usize = 256;
/// Most expression parameters accepted (`%0`..`%99`).
const MAX_PARAMETERS: usize = 100;

/// A reader's content filter as announced in SEDP.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ContentFilterProperty {
    /// The name of the reader's content-filtered topic.
    pub content_filtered_topic_name: String,
    /// The topic it filters (the topic of the SEDP announcement).
    pub related_topic_name: String,
    /// The filter language: [`ContentFilterProperty::DDSSQL`] for the DDS SQL subset.
    pub filter_class_name: String,
    /// The filter expression.
    pub filter_expression: String,
    /// The values of `%0`, `%1`, ...
    pub expression_parameters: Vec<String>,
}

impl ContentFilterProperty {
    /// The filter class of the DDS 1.4 Annex B language.
    pub const DDSSQL: &'static str = "DDSSQL";

    /// A DDSSQL filter.
    pub fn ddssql(
        content_filtered_topic_name: impl Into<String>,
        related_topic_name: impl Into<String>,
        filter_expression: impl Into<String>,
        expression_parameters: Vec<String>,
    ) -> Self {
        ContentFilterProperty {
            content_filtered_topic_name: content_filtered_topic_name.into(),
            related_topic_name: related_topic_name.into(),
            filter_class_name: Self::DDSSQL.into(),
            filter_expression: filter_expression.into(),
            expression_parameters,
        }
    }

    /// The filter signature (§9.6.4.1): MD5 of the three names, the expression and each parameter, each as
    /// its bytes followed by a NUL.
    pub fn signature(&self) -> [u8; 16] {
        let mut md5 = Md5::new();
        for s in [
            &self.content_filtered_topic_name,
            &self.related_topic_name,
            &self.filter_class_name,
            &self.filter_expression,
        ]
        .into_iter()
        .chain(&self.expression_parameters)
        {
            md5.update(s.as_bytes());
            md5.update([0u8]);
        }
        md5.finalize().into()
    }

    /// Appends the parameter.
    pub(crate) fn write(&self, w: &mut ParameterWriter<'_>) {
        w.param(pid::CONTENT_FILTER_PROPERTY, |p| {
            let origin = p.out.len();
            for s in [
                &self.content_filtered_topic_name,
                &self.related_topic_name,
                &self.filter_class_name,
                &self.filter_expression,
            ] {
                p.align_from(origin, 4);
                put_string(p, s);
            }
            p.align_from(origin, 4);
            p.u32(self.expression_parameters.len() as u32);
            for s in &self.expression_parameters {
                p.align_from(origin, 4);
                put_string(p, s);
            }
        });
    }

    /// Decodes the parameter's value. Names over 256 bytes or more than 100 parameters are refused.
    pub(crate) fn read(cur: &mut Cursor<'_>) -> Result<Self, WireError> {
        let name = |cur: &mut Cursor<'_>| -> Result<String, WireError> {
            cur.align(4)?;
            let s = cur.string()?;
            if s.len() > MAX_NAME {
                return Err(WireError::Invalid("content filter name longer than 256"));
            }
            Ok(s.to_owned())
        };
        let content_filtered_topic_name = name(cur)?;
        let related_topic_name = name(cur)?;
        let filter_class_name = name(cur)?;
        cur.align(4)?;
        let filter_expression = cur.string()?.to_owned();
        cur.align(4)?;
        let n = cur.u32()? as usize;
        if n > MAX_PARAMETERS {
            return Err(WireError::Invalid(
                "more than 100 content filter parameters",
            ));
        }
        let mut expression_parameters = Vec::with_capacity(n);
        for _ in 0..n {
            cur.align(4)?;
            expression_parameters.push(cur.string()?.to_owned());
        }
        Ok(ContentFilterProperty {
            content_filtered_topic_name,
            related_topic_name,
            filter_class_name,
            filter_expression,
            expression_parameters,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtps::messages::ParameterList;

    fn encode(f: &ContentFilterProperty, le: bool) -> Vec<u8> {
        let mut out = Vec::new();
        let mut w = ParameterWriter::new(&mut out, le);
        f.write(&mut w);
        w.finish();
        out
    }

    #[test]
    fn round_trips_in_both_byte_orders_and_refuses_truncation() {
        let f = ContentFilterProperty::ddssql(
            "Square_filtered",
            "Square",
            "x > %0 AND color = %1",
            vec!["10".into(), "'BLUE'".into()],
        );
        for le in [true, false] {
            let enc = encode(&f, le);
            let (pl, _) = ParameterList::parse(&enc, le).unwrap();
            let v = pl.get(pid::CONTENT_FILTER_PROPERTY).unwrap();
            assert_eq!(ContentFilterProperty::read(&mut pl.cursor(v)).unwrap(), f);
            for n in 0..v.len() {
                let _ = ContentFilterProperty::read(&mut pl.cursor(&v[..n]));
            }
        }
    }

    #[test]
    fn signature_is_md5_of_nul_terminated_fields() {
        let f = ContentFilterProperty::ddssql("a", "b", "x", vec!["1".into()]);
        let mut md5 = Md5::new();
        md5.update(b"a\0b\0DDSSQL\0x\0\x31\0");
        let want: [u8; 16] = md5.finalize().into();
        assert_eq!(f.signature(), want);
        let g = ContentFilterProperty::ddssql("a", "b", "x", vec!["2".into()]);
        assert_ne!(f.signature(), g.signature());
    }
}
