//! Random O-word programs: conditionals, counted and conditional loops with `continue`,
//! and calls of a subroutine, nested, over moves that read `#<_x>` and a parameter.
//! (`break` is left to `tests/dialect/oword_while_nested.ngc`: in rs274, a `break` of a
//! `while` makes every later `do` loop run once, a quirk pvtc does not copy.)

use super::*;
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Node {
    /// `G1` by (dx, dy) tenths from the position read through `#<_x>`, `#<_y>`.
    Move(i32, i32),
    /// `#<v> = [#<v> + k]`.
    Add(i32),
    /// `o<step> call [arg]`: a relative step of (arg, arg / 2).
    Call(i32),
    If(i32, Vec<Node>, Vec<Node>),
    Repeat(u32, Vec<Node>),
    /// Runs `times` times, skipping the rest of its body after `skip_after` iterations.
    While(u32, Option<u32>, Vec<Node>),
    DoWhile(u32, Vec<Node>),
}

fn node() -> impl Strategy<Value = Node> {
    let leaf = prop_oneof![
        3 => (-30i32..30, -30i32..30).prop_map(|(dx, dy)| Node::Move(dx, dy)),
        1 => (-3i32..4).prop_map(Node::Add),
        1 => (-20i32..20).prop_map(Node::Call),
    ];
    leaf.prop_recursive(3, 24, 4, |inner| {
        let body = prop::collection::vec(inner.clone(), 1..4);
        prop_oneof![
            (-3i32..4, body.clone(), prop::collection::vec(inner, 0..3))
                .prop_map(|(limit, then, otherwise)| Node::If(limit, then, otherwise)),
            (0u32..3, body.clone()).prop_map(|(times, body)| Node::Repeat(times, body)),
            (0u32..3, prop::option::of(0u32..3), body.clone())
                .prop_map(|(times, at, body)| Node::While(times, at, body)),
            (1u32..3, body).prop_map(|(times, body)| Node::DoWhile(times, body)),
        ]
    })
}

fn render(nodes: &[Node], labels: &mut u32, text: &mut String) {
    for node in nodes {
        let mut label = || {
            *labels += 1;
            *labels
        };
        match node {
            Node::Move(dx, dy) => text.push_str(&format!(
                "G1 X[#<_x> + {}] Y[#<_y> + {} + #<v> / 10]\n",
                f64::from(*dx) / 10.0,
                f64::from(*dy) / 10.0
            )),
            Node::Add(k) => text.push_str(&format!("#<v> = [#<v> + {k}]\n")),
            Node::Call(arg) => {
                text.push_str(&format!("o<step> call [{}]\n", f64::from(*arg) / 10.0))
            }
            Node::If(limit, then, otherwise) => {
                let l = label();
                text.push_str(&format!("o{l} if [#<v> GT {limit}]\n"));
                render(then, labels, text);
                if !otherwise.is_empty() {
                    text.push_str(&format!("o{l} else\n"));
                    render(otherwise, labels, text);
                }
                text.push_str(&format!("o{l} endif\n"));
            }
            Node::Repeat(times, body) => {
                let l = label();
                text.push_str(&format!("o{l} repeat [{times}]\n"));
                render(body, labels, text);
                text.push_str(&format!("o{l} endrepeat\n"));
            }
            Node::While(times, at, body) => {
                let l = label();
                text.push_str(&format!("#<w{l}> = 0\no{l} while [#<w{l}> LT {times}]\n"));
                text.push_str(&format!("#<w{l}> = [#<w{l}> + 1]\n"));
                if let Some(at) = at {
                    let b = label();
                    text.push_str(&format!(
                        "o{b} if [#<w{l}> GT {at}]\no{l} continue\no{b} endif\n"
                    ));
                }
                render(body, labels, text);
                text.push_str(&format!("o{l} endwhile\n"));
            }
            Node::DoWhile(times, body) => {
                let l = label();
                text.push_str(&format!("#<w{l}> = 0\no{l} do\n#<w{l}> = [#<w{l}> + 1]\n"));
                render(body, labels, text);
                text.push_str(&format!("o{l} while [#<w{l}> LT {times}]\n"));
            }
        }
    }
}

fn program(nodes: &[Node]) -> String {
    let mut text = String::from(
        "G21 G90 G17 G94 F300\nG1 X1 Y1\n#<v> = 0\n\
         o<step> sub\nG91 G1 X#1 Y[#1 / 2]\nG90\no<step> endsub\n",
    );
    render(nodes, &mut 0, &mut text);
    text.push_str("M2\n");
    text
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(32), ..ProptestConfig::default() })]

    #[test]
    fn random_control_flow_moves_as_rs274_moves(nodes in prop::collection::vec(node(), 1..6)) {
        let text = program(&nodes);
        let compared = compare_random(&text);
        prop_assert!(compared.is_ok(), "{}\n{}", text, compared.unwrap_err());
    }
}
