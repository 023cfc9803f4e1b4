//! A tiny document model rendered to Markdown and to one self-contained HTML file.

use std::fmt::Write as _;

/// A number with `prec` decimals or a dash.
#[must_use]
pub fn num(v: Option<f64>, prec: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.prec$}"),
        _ => "-".to_owned(),
    }
}

/// A block of a report.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// Heading of level 1..4.
    Heading(u8, String),
    /// A paragraph (plain text).
    Para(String),
    /// A bullet list.
    List(Vec<String>),
    /// A table.
    Table {
        /// Column headers.
        headers: Vec<String>,
        /// Rows of cells.
        rows: Vec<Vec<String>>,
    },
    /// A figure: caption, PNG file name (Markdown link) and SVG text (inlined in HTML).
    Figure {
        /// Caption.
        caption: String,
        /// PNG file name relative to the report.
        png: String,
        /// The SVG document.
        svg: String,
    },
}

fn md_cell(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

/// Markdown rendering.
#[must_use]
pub fn to_markdown(blocks: &[Block]) -> String {
    let mut out = String::new();
    for b in blocks {
        match b {
            Block::Heading(level, text) => {
                let _ = writeln!(out, "{} {text}\n", "#".repeat(usize::from(*level)));
            }
            Block::Para(text) => {
                let _ = writeln!(out, "{text}\n");
            }
            Block::List(items) => {
                for i in items {
                    let _ = writeln!(out, "- {i}");
                }
                out.push('\n');
            }
            Block::Table { headers, rows } => {
                let _ = writeln!(
                    out,
                    "| {} |",
                    headers
                        .iter()
                        .map(|h| md_cell(h))
                        .collect::<Vec<_>>()
                        .join(" | ")
                );
                let _ = writeln!(out, "|{}", "---|".repeat(headers.len()));
                for r in rows {
                    let _ = writeln!(
                        out,
                        "| {} |",
                        r.iter().map(|c| md_cell(c)).collect::<Vec<_>>().join(" | ")
                    );
                }
                out.push('\n');
            }
            Block::Figure { caption, png, .. } => {
                let _ = writeln!(out, "![{caption}]({png})\n\n*{caption}*\n");
            }
        }
    }
    out
}

/// Escapes text for HTML.
#[must_use]
pub fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            _ => o.push(c),
        }
    }
    o
}

/// Strips an XML declaration so the SVG can sit inside HTML.
fn inline_svg(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(k) => &svg[k..],
        None => svg,
    }
}

/// One self-contained HTML page (inline CSS, figures as inline SVG).
#[must_use]
pub fn to_html(title: &str, blocks: &[Block]) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n\
         <style>\nbody{{font-family:'DejaVu Sans',Verdana,sans-serif;max-width:1500px;margin:1em auto;padding:0 1em;color:#222}}\n\
         table{{border-collapse:collapse;margin:0.5em 0 1.2em}}\nth,td{{border:1px solid #bbb;padding:3px 7px;text-align:left;vertical-align:top;font-size:0.92em}}\n\
         th{{background:#eee}}\nfigure{{margin:1em 0 2em}}\nfigure svg{{max-width:100%;height:auto;border:1px solid #ddd}}\n\
         figcaption{{font-style:italic;margin-top:0.3em}}\n.warn{{color:#b00;font-weight:bold}}\n</style>\n</head>\n<body>\n",
        esc(title)
    );
    for b in blocks {
        match b {
            Block::Heading(level, text) => {
                let _ = writeln!(out, "<h{level}>{}</h{level}>", esc(text));
            }
            Block::Para(text) => {
                let class = if text.starts_with("WARNING") {
                    " class=\"warn\""
                } else {
                    ""
                };
                let _ = writeln!(out, "<p{class}>{}</p>", esc(text));
            }
            Block::List(items) => {
                out.push_str("<ul>\n");
                for i in items {
                    let _ = writeln!(out, "<li>{}</li>", esc(i));
                }
                out.push_str("</ul>\n");
            }
            Block::Table { headers, rows } => {
                out.push_str("<table>\n<thead><tr>");
                for h in headers {
                    let _ = write!(out, "<th>{}</th>", esc(h));
                }
                out.push_str("</tr></thead>\n<tbody>\n");
                for r in rows {
                    out.push_str("<tr>");
                    for c in r {
                        let _ = write!(out, "<td>{}</td>", esc(c));
                    }
                    out.push_str("</tr>\n");
                }
                out.push_str("</tbody>\n</table>\n");
            }
            Block::Figure { caption, svg, .. } => {
                let _ = writeln!(
                    out,
                    "<figure>\n{}\n<figcaption>{}</figcaption>\n</figure>",
                    inline_svg(svg),
                    esc(caption)
                );
            }
        }
    }
    out.push_str("</body>\n</html>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_both() {
        let blocks = vec![
            Block::Heading(1, "T <1>".into()),
            Block::Table {
                headers: vec!["a".into(), "b".into()],
                rows: vec![vec!["1|2".into(), "x".into()]],
            },
            Block::Figure {
                caption: "c".into(),
                png: "m.png".into(),
                svg: "<?xml version=\"1.0\"?><svg></svg>".into(),
            },
        ];
        let md = to_markdown(&blocks);
        assert!(md.contains("| 1\\|2 | x |"));
        assert!(md.contains("![c](m.png)"));
        let html = to_html("t", &blocks);
        assert!(html.contains("<h1>T &lt;1&gt;</h1>"));
        assert!(html.contains("<figure>\n<svg></svg>"));
        assert!(!html.contains("<?xml"));
    }
}
