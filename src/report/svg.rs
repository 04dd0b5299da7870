//! The review pack's SVG gate: every figure is parsed and written out again from what was
//! understood, so nothing read from a results folder reaches the page as it was found.
//!
//! A results folder travels between colleagues, so its `figures/*.svg` are untrusted input. The
//! page inlines SVG, and inline SVG may carry script (`<script>`, `onload=`), pull resources from
//! the network (`<image href="http://…">`, `url(…)` in a style) or expand entities (`<!DOCTYPE>`).
//! Rather than search for what is dangerous, [`clean`] accepts only the small vocabulary the
//! figures Shoal draws use (plotters' SVG backend: shapes, text, embedded PNG rasters) and refuses
//! the whole figure on anything else, naming what it met. The accepted document is re-serialised
//! from its parsed elements, attributes (each value checked against the characters its kind may
//! hold) and text, escaped again.

use std::fmt::Write as _;

/// The largest figure accepted, bytes (a full-resolution map figure is ~2 MB).
pub const MAX_SVG_BYTES: usize = 64 << 20;
/// Deepest element nesting accepted.
const MAX_DEPTH: usize = 32;

/// Elements a Shoal figure may contain.
const ELEMENTS: [&str; 13] =
    ["svg", "g", "rect", "line", "polyline", "polygon", "path", "circle", "ellipse", "text", "tspan", "image", "title"];

/// The characters an attribute's value may hold, by kind.
#[derive(Clone, Copy)]
enum Kind {
    /// Numbers with optional units and lists of them (`0.76em`, `10`, `0 0 1010 400`).
    Number,
    /// Geometry and transforms (`M 1 2 L 3 4`, `rotate(270, 8, 256)`).
    Geometry,
    /// A colour (`#FFFFFF`, `none`, `rgb(1,2,3)`), never a `url(…)`.
    Colour,
    /// A word or words (`sans-serif`, `start`, `middle`).
    Words,
    /// `image-rendering:pixelated` and nothing else.
    Style,
    /// An embedded PNG: `data:image/png;base64,…`.
    PngData,
    /// The SVG namespace, which is dropped on output.
    Namespace,
}

fn kind_of(attribute: &str) -> Option<Kind> {
    Some(match attribute {
        "x" | "y" | "width" | "height" | "cx" | "cy" | "r" | "rx" | "ry" | "x1" | "y1" | "x2" | "y2" | "dx" | "dy"
        | "stroke-width" | "opacity" | "fill-opacity" | "stroke-opacity" | "font-size" | "stroke-dasharray" => {
            Kind::Number
        }
        "viewBox" | "points" | "d" | "transform" => Kind::Geometry,
        "fill" | "stroke" => Kind::Colour,
        "font-family"
        | "font-weight"
        | "font-style"
        | "text-anchor"
        | "dominant-baseline"
        | "stroke-linecap"
        | "stroke-linejoin"
        | "preserveAspectRatio" => Kind::Words,
        "style" => Kind::Style,
        "href" | "xlink:href" => Kind::PngData,
        "xmlns" | "xmlns:xlink" => Kind::Namespace,
        _ => return None,
    })
}

fn value_allowed(kind: Kind, element: &str, value: &str) -> bool {
    let all = |ok: fn(char) -> bool| value.chars().all(ok);
    match kind {
        Kind::Number => all(|c| c.is_ascii_alphanumeric() || " .,+-%".contains(c)),
        Kind::Geometry => all(|c| c.is_ascii_alphanumeric() || " .,+-()".contains(c)) && !has_url(value),
        Kind::Colour => all(|c| c.is_ascii_alphanumeric() || " #.,()%".contains(c)) && !has_url(value),
        Kind::Words => all(|c| c.is_ascii_alphanumeric() || " ,-".contains(c)),
        Kind::Style => value.trim().trim_end_matches(';') == "image-rendering:pixelated",
        Kind::PngData => {
            element == "image"
                && value.strip_prefix("data:image/png;base64,").is_some_and(|b64| {
                    b64.bytes().all(|b| b.is_ascii_alphanumeric() || matches!(b, b'+' | b'/' | b'=' | b'\n' | b'\r'))
                })
        }
        Kind::Namespace => matches!(value, "http://www.w3.org/2000/svg" | "http://www.w3.org/1999/xlink"),
    }
}

fn has_url(value: &str) -> bool {
    value.to_ascii_lowercase().contains("url")
}

/// Why a figure was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("not a figure Shoal draws: {0}")]
pub struct Refused(pub String);

/// The SVG `svg` re-written from what was understood: only Shoal's figure vocabulary, every
/// value checked, text escaped, comments and the XML prolog dropped, no namespace attributes
/// (HTML parses inline SVG without them). Anything else refuses the whole figure.
pub fn clean(svg: &str) -> Result<String, Refused> {
    let refuse = |m: String| Err(Refused(m));
    if svg.len() > MAX_SVG_BYTES {
        return refuse(format!("{} bytes (at most {MAX_SVG_BYTES})", svg.len()));
    }
    let mut out = String::with_capacity(svg.len());
    let mut open: Vec<&str> = Vec::new();
    let mut rest = svg;
    let mut seen_root = false;
    while !rest.is_empty() {
        let Some(lt) = rest.find('<') else {
            text(rest, &open, &mut out)?;
            break;
        };
        text(&rest[..lt], &open, &mut out)?;
        rest = &rest[lt..];
        if let Some(after) = rest.strip_prefix("<?xml") {
            if seen_root {
                return refuse("an XML declaration inside the document".into());
            }
            let Some(end) = after.find("?>") else { return refuse("an unterminated XML declaration".into()) };
            rest = &after[end + 2..];
        } else if let Some(after) = rest.strip_prefix("<!--") {
            let Some(end) = after.find("-->") else { return refuse("an unterminated comment".into()) };
            rest = &after[end + 3..];
        } else if rest.starts_with("<!") || rest.starts_with("<?") {
            return refuse(format!("`{}`", excerpt(rest)));
        } else if let Some(after) = rest.strip_prefix("</") {
            let Some(end) = after.find('>') else { return refuse("an unterminated closing tag".into()) };
            let name = after[..end].trim();
            if open.pop() != Some(name) {
                return refuse(format!("`</{}>` does not close the open element", excerpt(name)));
            }
            let _ = write!(out, "</{name}>");
            rest = &after[end + 1..];
        } else {
            let (tag, after) = start_tag(&rest[1..])?;
            if open.is_empty() {
                if seen_root || tag.name != "svg" {
                    return refuse(format!("`<{}>` at the top level (only one <svg>)", tag.name));
                }
                seen_root = true;
            }
            out.push('<');
            out.push_str(tag.name);
            for (name, value) in &tag.attributes {
                if matches!(kind_of(name), Some(Kind::Namespace)) {
                    continue;
                }
                let _ = write!(out, " {name}=\"{}\"", super::html::escape(value));
            }
            if tag.empty {
                out.push_str("/>");
            } else {
                out.push('>');
                open.push(tag.name);
                if open.len() > MAX_DEPTH {
                    return refuse(format!("elements nested deeper than {MAX_DEPTH}"));
                }
            }
            rest = after;
        }
    }
    if let Some(e) = open.last() {
        return refuse(format!("`<{e}>` is never closed"));
    }
    if !seen_root {
        return refuse("no <svg> element".into());
    }
    Ok(out)
}

/// A start tag, parsed: name, attributes (values unescaped and checked), self-closing or not.
struct StartTag<'a> {
    name: &'a str,
    attributes: Vec<(&'a str, String)>,
    empty: bool,
}

/// Parse the start tag at the beginning of `s` (after its `<`); returns it and what follows it.
fn start_tag(s: &str) -> Result<(StartTag<'_>, &str), Refused> {
    let name_end = s.find(|c: char| !(c.is_ascii_alphanumeric() || c == ':' || c == '-')).unwrap_or(s.len());
    let name = &s[..name_end];
    if !ELEMENTS.contains(&name) {
        return Err(Refused(format!("the element `<{}>`", excerpt(name))));
    }
    let mut rest = &s[name_end..];
    let mut attributes: Vec<(&str, String)> = Vec::new();
    loop {
        rest = rest.trim_start();
        if let Some(after) = rest.strip_prefix("/>") {
            return Ok((StartTag { name, attributes, empty: true }, after));
        }
        if let Some(after) = rest.strip_prefix('>') {
            return Ok((StartTag { name, attributes, empty: false }, after));
        }
        let key_end = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == ':' || c == '-')).unwrap_or(rest.len());
        let key = &rest[..key_end];
        if key.is_empty() {
            return Err(Refused(format!("`<{name}` is malformed near `{}`", excerpt(rest))));
        }
        let Some(kind) = kind_of(key) else {
            return Err(Refused(format!("the attribute `{}` on <{name}>", excerpt(key))));
        };
        rest = rest[key_end..].trim_start();
        let Some(after_eq) = rest.strip_prefix('=') else {
            return Err(Refused(format!("the attribute `{key}` on <{name}> has no value")));
        };
        let after_eq = after_eq.trim_start();
        let Some(quote) = after_eq.chars().next().filter(|q| *q == '"' || *q == '\'') else {
            return Err(Refused(format!("the attribute `{key}` on <{name}> is not quoted")));
        };
        let body = &after_eq[1..];
        let Some(end) = body.find(quote) else {
            return Err(Refused(format!("the attribute `{key}` on <{name}> is not closed")));
        };
        let value = unescape(&body[..end])?;
        if !value_allowed(kind, name, &value) {
            return Err(Refused(format!("`{key}=\"{}\"` on <{name}>", excerpt(&value))));
        }
        if attributes.iter().any(|(k, _)| *k == key) {
            return Err(Refused(format!("the attribute `{key}` twice on <{name}>")));
        }
        attributes.push((key, value));
        rest = &body[end + 1..];
    }
}

/// Text between tags: allowed only inside `text`, `tspan` and `title` (whitespace anywhere),
/// unescaped and escaped again.
fn text(raw: &str, open: &[&str], out: &mut String) -> Result<(), Refused> {
    if raw.trim().is_empty() {
        // Whitespace is kept inside the document and dropped around it.
        if !open.is_empty() {
            out.push_str(raw);
        }
        return Ok(());
    }
    if !matches!(open.last(), Some(&("text" | "tspan" | "title"))) {
        return Err(Refused(format!("text `{}` outside a text element", excerpt(raw.trim()))));
    }
    out.push_str(&super::html::escape(&unescape(raw)?));
    Ok(())
}

/// XML's five named entities and numeric character references, decoded; any other `&` refuses.
fn unescape(s: &str) -> Result<String, Refused> {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(amp) = rest.find('&') {
        out.push_str(&rest[..amp]);
        let after = &rest[amp + 1..];
        let Some(semi) = after.find(';').filter(|&i| i <= 10) else {
            return Err(Refused(format!("a bare `&` in `{}`", excerpt(s))));
        };
        let entity = &after[..semi];
        let c = match entity {
            "lt" => '<',
            "gt" => '>',
            "amp" => '&',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(hex) = entity.strip_prefix("#x").or_else(|| entity.strip_prefix("#X")) {
                    u32::from_str_radix(hex, 16).ok()
                } else {
                    entity.strip_prefix('#').and_then(|d| d.parse::<u32>().ok())
                };
                code.and_then(char::from_u32)
                    .filter(|c| !c.is_control() || c.is_whitespace())
                    .ok_or_else(|| Refused(format!("the entity `&{};`", excerpt(entity))))?
            }
        };
        out.push(c);
        rest = &after[semi + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// The first characters of `s`, for a message (control characters shown escaped).
fn excerpt(s: &str) -> String {
    let short: String = s.chars().take(40).collect();
    let mut e = short.escape_debug().to_string();
    if s.chars().count() > 40 {
        e.push('…');
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    const FIGURE: &str = "<?xml version=\"1.0\"?>\n<svg width=\"10\" height=\"8\" viewBox=\"0 0 10 8\" \
        xmlns=\"http://www.w3.org/2000/svg\">\n<!-- drawn -->\n<rect x=\"0\" y=\"0\" width=\"10\" height=\"8\" \
        fill=\"#FFFFFF\" stroke=\"none\"/>\n<text x=\"1\" y=\"2\" dy=\"0.76em\" font-family=\"sans-serif\" \
        transform=\"rotate(270, 8, 256)\">chl &lt; 5 mg m⁻³ &amp; A − B</text>\n<image x=\"1\" y=\"1\" \
        width=\"2\" height=\"2\" style=\"image-rendering:pixelated\" href=\"data:image/png;base64,iVBOR+/w==\"/>\n\
        <polyline points=\"1,2 3,4\" stroke-width=\"1\" opacity=\"0.5\"/>\n</svg>\n";

    #[test]
    fn a_shoal_figure_passes_with_its_text_and_raster() {
        let out = clean(FIGURE).unwrap();
        assert!(out.starts_with("<svg width=\"10\" height=\"8\" viewBox=\"0 0 10 8\">"), "{out}");
        assert!(out.contains(">chl &lt; 5 mg m⁻³ &amp; A − B</text>"), "{out}");
        assert!(out.contains("href=\"data:image/png;base64,iVBOR+/w==\""));
        assert!(!out.contains("<!--") && !out.contains("<?xml") && !out.contains("xmlns"));
        // What was written out reads back the same: the writer's output is inside the gate.
        assert_eq!(clean(&out).unwrap(), out);
    }

    #[test]
    fn script_network_and_entities_are_refused_with_what_was_met() {
        let cases = [
            ("<svg><script>alert(1)</script></svg>", "`<script>`"),
            ("<svg onload=\"alert(1)\"></svg>", "`onload`"),
            ("<svg><image href=\"http://example.com/x.png\"/></svg>", "href"),
            ("<svg><image xlink:href=\"javascript:alert(1)\"/></svg>", "xlink:href"),
            ("<svg><rect fill=\"url(http://e.com/#a)\"/></svg>", "fill"),
            ("<svg><rect style=\"background:url(http://e.com)\"/></svg>", "style"),
            ("<!DOCTYPE svg [<!ENTITY a \"b\">]><svg>&a;</svg>", "DOCTYPE"),
            ("<svg><foreignObject><div/></foreignObject></svg>", "foreignObject"),
            ("<svg><text>a</text></svg><script>x</script>", "`<script>`"),
            ("<svg></svg><svg></svg>", "top level"),
            ("<svg><text>&#0;</text></svg>", "entity"),
            ("<svg><rect x='1' x='2'/></svg>", "twice"),
            ("<svg><g>", "never closed"),
            ("<svg>plain text</svg>", "outside a text element"),
            ("<svg><![CDATA[x]]></svg>", "CDATA"),
            ("<svg><text>a &b</text></svg>", "bare `&`"),
            ("<svg><rect x=\"1\" y=1/></svg>", "not quoted"),
            ("<svg><set attributeName=\"href\" to=\"javascript:x\"/></svg>", "`<set>`"),
        ];
        for (svg, said) in cases {
            match clean(svg) {
                Err(Refused(m)) => assert!(m.contains(said), "{svg}: {m}"),
                Ok(out) => panic!("{svg} passed as {out}"),
            }
        }
    }

    #[test]
    fn an_oversized_or_deeply_nested_figure_is_refused() {
        let deep = format!("<svg>{}{}</svg>", "<g>".repeat(40), "</g>".repeat(40));
        assert!(clean(&deep).unwrap_err().0.contains("deeper"));
        let big = format!("<svg>{}</svg>", " ".repeat(MAX_SVG_BYTES));
        assert!(clean(&big).unwrap_err().0.contains("bytes"));
    }
}
