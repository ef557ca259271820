//! A small element tree written with quick-xml (the exporters build the document as data,
//! then write it once), and the number format every exported value uses.

use quick_xml::Writer;
use quick_xml::events::{BytesDecl, BytesText, Event};

/// One node of a document.
#[derive(Clone, Debug)]
pub enum Node {
    El(El),
    Comment(String),
}

/// An element: name, attributes in order, children, text.
#[derive(Clone, Debug, Default)]
pub struct El {
    pub name: String,
    pub attrs: Vec<(String, String)>,
    pub children: Vec<Node>,
    pub text: Option<String>,
}

impl El {
    pub fn new(name: &str) -> El {
        El {
            name: name.to_string(),
            ..El::default()
        }
    }

    pub fn attr(mut self, key: &str, value: impl Into<String>) -> El {
        self.attrs.push((key.to_string(), value.into()));
        self
    }

    pub fn child(mut self, c: El) -> El {
        self.children.push(Node::El(c));
        self
    }

    pub fn comment(mut self, text: impl Into<String>) -> El {
        self.children.push(Node::Comment(text.into()));
        self
    }

    pub fn text(mut self, t: impl Into<String>) -> El {
        self.text = Some(t.into());
        self
    }

    /// `<name>text</name>`.
    pub fn leaf(name: &str, t: impl Into<String>) -> El {
        El::new(name).text(t)
    }

    pub fn push(&mut self, c: El) {
        self.children.push(Node::El(c));
    }
}

fn write_node(w: &mut Writer<Vec<u8>>, n: &Node) -> std::io::Result<()> {
    match n {
        Node::Comment(c) => {
            // "--" may not appear inside an XML comment.
            let safe = format!(" {} ", c.replace("--", "- -"));
            w.write_event(Event::Comment(BytesText::from_escaped(safe)))
        }
        Node::El(e) => {
            let attrs = e.attrs.iter().map(|(k, v)| (k.as_str(), v.as_str()));
            let start = w.create_element(e.name.as_str()).with_attributes(attrs);
            match (&e.text, e.children.is_empty()) {
                (Some(t), _) => start.write_text_content(BytesText::new(t)).map(|_| ()),
                (None, true) => start.write_empty().map(|_| ()),
                (None, false) => start
                    .write_inner_content(|w| {
                        for c in &e.children {
                            write_node(w, c)?;
                        }
                        Ok(())
                    })
                    .map(|_| ()),
            }
        }
    }
}

/// The document: an XML declaration, leading comments, the root element.
pub fn document(header: &[String], root: &El) -> String {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    // Writing into a Vec cannot fail.
    let _ = w.write_event(Event::Decl(BytesDecl::new("1.0", Some("utf-8"), None)));
    for h in header {
        let _ = write_node(&mut w, &Node::Comment(h.clone()));
    }
    let _ = write_node(&mut w, &Node::El(root.clone()));
    let mut s = String::from_utf8(w.into_inner()).unwrap_or_default();
    s.push('\n');
    s
}

/// A number as the exports write it: the shortest form that reads back to the same f64.
pub fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".into();
    }
    format!("{x:?}")
}

/// Several numbers separated by spaces.
pub fn nums(xs: &[f64]) -> String {
    xs.iter().map(|x| num(*x)).collect::<Vec<_>>().join(" ")
}
