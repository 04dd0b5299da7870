//! Text placed inside HTML, SVG or XML markup (the review pack, figures, GDAL's XML metadata in
//! GeoTIFF files): one escaping rule for all of them, so no name a user chose can open a tag or an
//! attribute.

/// `s` with `&`, `<`, `>` and `"` as character entities: safe as element text and inside a
/// double-quoted attribute value (HTML 5, XML 1.0 §2.4).
///
/// ```
/// assert_eq!(shoal::markup::escape(r#"<a href="x">&</a>"#), "&lt;a href=&quot;x&quot;&gt;&amp;&lt;/a&gt;");
/// ```
#[must_use]
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
