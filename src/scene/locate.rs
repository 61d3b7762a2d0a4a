//! Finds the line of a field in the scene text, so that errors found after parsing
//! (an unknown material name, a radius of zero) still point at the line.

use toml_edit::{ImDocument, Item, Value};

use super::error::{FieldPath, FieldSegment, line_column};

/// Line (1-based) of the deepest part of `path` that exists in `text`.
pub fn line_of(text: &str, path: &FieldPath) -> Option<usize> {
    let doc = ImDocument::parse(text).ok()?;
    let mut best: Option<std::ops::Range<usize>> = None;
    let mut item: Option<Node<'_>> = Some(Node::Item(doc.as_item()));
    for seg in &path.0 {
        let Some(node) = item.take() else { break };
        let next = match (node, seg) {
            (Node::Item(Item::Table(t)), FieldSegment::Key(k)) => {
                if let Some(key) = t.key(k) {
                    best = key.span().or(best);
                }
                t.get(k).map(Node::Item)
            }
            (Node::Item(Item::Value(v)) | Node::Value(v), FieldSegment::Key(k)) => match v {
                Value::InlineTable(t) => {
                    if let Some(key) = t.key(k) {
                        best = key.span().or(best);
                    }
                    t.get(k).map(Node::Value)
                }
                _ => None,
            },
            (Node::Item(Item::ArrayOfTables(a)), FieldSegment::Index(i)) => a.get(*i).map(|t| {
                best = t.span().or(best.clone());
                Node::Table(t)
            }),
            (Node::Table(t), FieldSegment::Key(k)) => {
                if let Some(key) = t.key(k) {
                    best = key.span().or(best);
                }
                t.get(k).map(Node::Item)
            }
            (Node::Item(Item::Value(v)) | Node::Value(v), FieldSegment::Index(i)) => match v {
                Value::Array(a) => a.get(*i).map(|v| {
                    best = v.span().or(best.clone());
                    Node::Value(v)
                }),
                _ => None,
            },
            _ => None,
        };
        item = next;
    }
    best.map(|span| line_column(text, span.start).0)
}

#[derive(Clone, Copy)]
enum Node<'a> {
    Item(&'a Item),
    Value(&'a Value),
    Table(&'a toml_edit::Table),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_keys_tables_and_arrays() {
        let text = "[simulation]\ndt = 1e-5\n\n[[wall]]\nname = \"a\"\n\n[[wall]]\nname = \"b\"\nmotion = { kind = \"rotation\", rpm = 0 }\n";
        let p = |s: &[FieldSegment]| FieldPath(s.to_vec());
        let k = |s: &str| FieldSegment::Key(s.into());
        assert_eq!(line_of(text, &p(&[k("simulation"), k("dt")])), Some(2));
        assert_eq!(
            line_of(text, &p(&[k("wall"), FieldSegment::Index(1), k("name")])),
            Some(8)
        );
        assert_eq!(
            line_of(
                text,
                &p(&[k("wall"), FieldSegment::Index(1), k("motion"), k("rpm")])
            ),
            Some(9)
        );
        // A missing field points at its table.
        assert_eq!(
            line_of(
                text,
                &p(&[k("wall"), FieldSegment::Index(1), k("material")])
            ),
            Some(7)
        );
    }
}
