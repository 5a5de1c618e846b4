//! A strict checker of the report's HTML: what a validator would reject in pages of this shape.

use std::collections::BTreeSet;

const VOID: [&str; 13] = [
    "area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr",
];

fn check_text(text: &str, at: usize) -> Result<(), String> {
    let mut rest = text;
    while let Some(i) = rest.find('&') {
        let after = &rest[i + 1..];
        let end = after
            .find(';')
            .ok_or_else(|| format!("bare & near byte {at}: {:?}", &rest[i..(i + 20).min(rest.len())]))?;
        let name = &after[..end];
        let ok = (!name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric()) && name.len() < 10)
            || (name.starts_with('#') && name[1..].chars().all(|c| c.is_ascii_digit()) && name.len() > 1);
        if !ok {
            return Err(format!("bad entity &{name}; near byte {at}"));
        }
        rest = &after[end + 1..];
    }
    if text.contains('>') {
        return Err(format!("raw > in text near byte {at}"));
    }
    Ok(())
}

/// Checks that elements nest and close, attributes are quoted and escaped, ids are unique, every
/// `href="#…"` has its target, text has no raw `<`, `>` or bare `&`, and `<svg>` content closes its own tags.
pub fn check_html(html: &str) -> Result<(), String> {
    if !html.starts_with("<!DOCTYPE html>\n") {
        return Err("no doctype".into());
    }
    if !html.contains("<meta charset=\"utf-8\">") {
        return Err("no charset".into());
    }
    let mut stack: Vec<String> = Vec::new();
    let mut ids = BTreeSet::new();
    let mut hrefs = Vec::new();
    let mut pos = "<!DOCTYPE html>\n".len();
    while pos < html.len() {
        let Some(lt) = html[pos..].find('<') else {
            check_text(&html[pos..], pos)?;
            break;
        };
        check_text(&html[pos..pos + lt], pos)?;
        let start = pos + lt;
        let end = start + html[start..].find('>').ok_or("unclosed tag")?;
        let tag = &html[start + 1..end];
        pos = end + 1;
        if let Some(name) = tag.strip_prefix('/') {
            let open = stack
                .pop()
                .ok_or_else(|| format!("</{name}> without an open element at byte {start}"))?;
            if open != name {
                return Err(format!("</{name}> closes <{open}> at byte {start}"));
            }
            continue;
        }
        let self_closing = tag.ends_with('/');
        let tag = tag.trim_end_matches('/');
        let name_end = tag.find(|c: char| c.is_whitespace()).unwrap_or(tag.len());
        let name = &tag[..name_end];
        if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric()) {
            return Err(format!("bad tag name {name:?} at byte {start}"));
        }
        // Attributes: name="value", value without raw < or ".
        let mut attrs = tag[name_end..].trim();
        while !attrs.is_empty() {
            if let Some(rest) = ["hidden ", "open "]
                .iter()
                .find_map(|b| format!("{attrs} ").strip_prefix(b).map(str::to_string))
            {
                attrs = attrs[attrs.len() - rest.trim_end().len()..].trim_start();
                continue;
            }
            let eq = attrs
                .find("=\"")
                .ok_or_else(|| format!("unquoted attribute in <{name}> at byte {start}: {attrs:?}"))?;
            let key = attrs[..eq].trim();
            if !key.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == ':') || key.is_empty() {
                return Err(format!("bad attribute name {key:?} at byte {start}"));
            }
            let rest = &attrs[eq + 2..];
            let close = rest.find('"').ok_or("unterminated attribute")?;
            let value = &rest[..close];
            if value.contains('<') {
                return Err(format!("raw < in attribute {key} at byte {start}"));
            }
            check_text(value, start)?;
            if key == "id" && !ids.insert(value.to_string()) {
                return Err(format!("duplicate id {value:?}"));
            }
            if key == "href" {
                hrefs.push(value.to_string());
            }
            attrs = rest[close + 1..].trim_start();
        }
        let in_svg = stack.iter().any(|t| t == "svg");
        if self_closing && !in_svg && !VOID.contains(&name) {
            return Err(format!("self-closing <{name}/> outside SVG at byte {start}"));
        }
        if VOID.contains(&name) || self_closing {
            continue;
        }
        if name == "script" || name == "style" {
            let close = format!("</{name}>");
            let body_end = pos + html[pos..].find(&close).ok_or("unclosed raw text element")?;
            pos = body_end + close.len();
            continue;
        }
        stack.push(name.to_string());
    }
    if !stack.is_empty() {
        return Err(format!("unclosed elements: {stack:?}"));
    }
    for h in hrefs {
        let target = h.strip_prefix('#').ok_or_else(|| format!("non-fragment link {h:?}"))?;
        if !ids.contains(target) {
            return Err(format!("link to missing id {target:?}"));
        }
    }
    Ok(())
}

/// The `<h2>` and `<h3>` headings of a page, one per line (markup inside them kept).
pub fn outline(html: &str) -> String {
    let mut out = String::new();
    let mut rest = html;
    while let Some(i) = rest.find("<h") {
        let after = &rest[i + 2..];
        let lvl = after.chars().next().unwrap_or(' ');
        if (lvl == '2' || lvl == '3') && after[1..].starts_with('>') {
            let body = &after[2..];
            let end = body.find("</h").unwrap_or(body.len());
            out.push_str(if lvl == '2' { "## " } else { "### " });
            out.push_str(&body[..end]);
            out.push('\n');
        }
        rest = after;
    }
    out
}
