//! A reader and matcher for the ISO 14977 EBNF of `grammars/`, so tests check output
//! against the grammar file itself rather than a hand-written copy of it.
//!
//! Owns parsing productions (`name = … ;`, comments `(* … *)`) and matching text against
//! one: terminals `"…"`, concatenation `,`, alternatives `|`, exceptions `a - b`,
//! options `[ … ]`, repetitions `{ … }` and `n * a`, groups `( … )`, and two special
//! sequences, `? line feed ?` (one `\n`) and `? any character ?`. A matcher answers
//! whether the whole text is the production; it must not know what the grammar is about.

use std::collections::{BTreeMap, BTreeSet};

/// An EBNF expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A terminal string.
    Terminal(Vec<char>),
    /// A production named.
    Name(String),
    /// Each in turn.
    Sequence(Vec<Expr>),
    /// Any one of them.
    Choice(Vec<Expr>),
    /// What the first matches, unless the second matches the same text.
    Except(Box<Expr>, Box<Expr>),
    /// Zero or one.
    Optional(Box<Expr>),
    /// Zero or more.
    Repeat(Box<Expr>),
    /// Exactly n.
    Times(usize, Box<Expr>),
    /// One line feed.
    LineFeed,
    /// Any one character.
    AnyChar,
}

/// The productions of a grammar, by name.
#[derive(Debug, Clone, PartialEq)]
pub struct Grammar {
    /// Each production's expression.
    pub productions: BTreeMap<String, Expr>,
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Name(String),
    Terminal(String),
    Special(String),
    Number(usize),
    Symbol(char),
}

fn tokens(text: &str) -> Result<Vec<Token>, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c == '(' && chars.get(i + 1) == Some(&'*') {
            let end = (i + 2..chars.len().saturating_sub(1))
                .find(|&j| chars[j] == '*' && chars[j + 1] == ')')
                .ok_or("an unclosed comment")?;
            i = end + 2;
        } else if c == '"' || c == '\'' || c == '?' {
            let end = (i + 1..chars.len())
                .find(|&j| chars[j] == c)
                .ok_or_else(|| format!("an unclosed {c}"))?;
            let body: String = chars[i + 1..end].iter().collect();
            out.push(if c == '?' {
                Token::Special(body.trim().to_string())
            } else {
                Token::Terminal(body)
            });
            i = end + 1;
        } else if c.is_ascii_digit() {
            let end = (i..chars.len())
                .find(|&j| !chars[j].is_ascii_digit())
                .unwrap_or(chars.len());
            let digits: String = chars[i..end].iter().collect();
            out.push(Token::Number(digits.parse().map_err(|e| format!("{e}"))?));
            i = end;
        } else if c.is_alphabetic() || c == '_' {
            let end = (i..chars.len())
                .find(|&j| !(chars[j].is_alphanumeric() || chars[j] == '_'))
                .unwrap_or(chars.len());
            out.push(Token::Name(chars[i..end].iter().collect()));
            i = end;
        } else if "=,|-{}[]();*".contains(c) {
            out.push(Token::Symbol(c));
            i += 1;
        } else {
            return Err(format!("unexpected {c:?}"));
        }
    }
    Ok(out)
}

struct Parser {
    tokens: Vec<Token>,
    at: usize,
}

impl Parser {
    fn peek(&self) -> Option<&Token> {
        self.tokens.get(self.at)
    }

    fn eat(&mut self, symbol: char) -> bool {
        if self.peek() == Some(&Token::Symbol(symbol)) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    fn expect(&mut self, symbol: char) -> Result<(), String> {
        if self.eat(symbol) {
            Ok(())
        } else {
            Err(format!("expected {symbol:?} at {:?}", self.peek()))
        }
    }

    fn choice(&mut self) -> Result<Expr, String> {
        let mut options = vec![self.sequence()?];
        while self.eat('|') {
            options.push(self.sequence()?);
        }
        Ok(if options.len() == 1 {
            options.pop().unwrap()
        } else {
            Expr::Choice(options)
        })
    }

    fn sequence(&mut self) -> Result<Expr, String> {
        let mut items = vec![self.except()?];
        while self.eat(',') {
            items.push(self.except()?);
        }
        Ok(if items.len() == 1 {
            items.pop().unwrap()
        } else {
            Expr::Sequence(items)
        })
    }

    fn except(&mut self) -> Result<Expr, String> {
        let mut term = self.term()?;
        // `a - b - c`: what a matches, unless b or c matches it.
        while self.eat('-') {
            term = Expr::Except(Box::new(term), Box::new(self.term()?));
        }
        Ok(term)
    }

    fn term(&mut self) -> Result<Expr, String> {
        if let Some(&Token::Number(n)) = self.peek() {
            self.at += 1;
            self.expect('*')?;
            return Ok(Expr::Times(n, Box::new(self.primary()?)));
        }
        self.primary()
    }

    fn primary(&mut self) -> Result<Expr, String> {
        let token = self.peek().cloned().ok_or("unexpected end")?;
        self.at += 1;
        Ok(match token {
            Token::Terminal(t) => Expr::Terminal(t.chars().collect()),
            Token::Name(n) => Expr::Name(n),
            Token::Special(s) => match s.as_str() {
                "line feed" => Expr::LineFeed,
                "any character" => Expr::AnyChar,
                other => return Err(format!("unknown special sequence ? {other} ?")),
            },
            Token::Symbol('{') => {
                let e = self.choice()?;
                self.expect('}')?;
                Expr::Repeat(Box::new(e))
            }
            Token::Symbol('[') => {
                let e = self.choice()?;
                self.expect(']')?;
                Expr::Optional(Box::new(e))
            }
            Token::Symbol('(') => {
                let e = self.choice()?;
                self.expect(')')?;
                e
            }
            other => return Err(format!("unexpected {other:?}")),
        })
    }
}

impl Grammar {
    /// Reads the productions of `text`; every name used must be defined.
    pub fn parse(text: &str) -> Result<Grammar, String> {
        let mut parser = Parser {
            tokens: tokens(text)?,
            at: 0,
        };
        let mut productions = BTreeMap::new();
        while let Some(token) = parser.peek().cloned() {
            let Token::Name(name) = token else {
                return Err(format!("expected a production name at {token:?}"));
            };
            parser.at += 1;
            parser.expect('=')?;
            let expr = parser.choice()?;
            parser.expect(';')?;
            if productions.insert(name.clone(), expr).is_some() {
                return Err(format!("{name} is defined twice"));
            }
        }
        let grammar = Grammar { productions };
        for expr in grammar.productions.values() {
            grammar.check_names(expr)?;
        }
        Ok(grammar)
    }

    fn check_names(&self, expr: &Expr) -> Result<(), String> {
        match expr {
            Expr::Name(n) if !self.productions.contains_key(n) => {
                Err(format!("{n} is not defined"))
            }
            Expr::Sequence(v) | Expr::Choice(v) => v.iter().try_for_each(|e| self.check_names(e)),
            Expr::Except(a, b) => self.check_names(a).and_then(|()| self.check_names(b)),
            Expr::Optional(e) | Expr::Repeat(e) | Expr::Times(_, e) => self.check_names(e),
            _ => Ok(()),
        }
    }

    /// True when the whole of `text` is production `name`.
    pub fn matches(&self, name: &str, text: &str) -> bool {
        let chars: Vec<char> = text.chars().collect();
        let expr = &self.productions[name];
        self.ends(expr, &chars, 0).contains(&chars.len())
    }

    /// Every position at which a match of `expr` starting at `start` can end.
    fn ends(&self, expr: &Expr, text: &[char], start: usize) -> BTreeSet<usize> {
        let mut out = BTreeSet::new();
        match expr {
            Expr::Terminal(t) => {
                if text[start..].starts_with(t) {
                    out.insert(start + t.len());
                }
            }
            Expr::LineFeed => {
                if text.get(start) == Some(&'\n') {
                    out.insert(start + 1);
                }
            }
            Expr::AnyChar => {
                if start < text.len() {
                    out.insert(start + 1);
                }
            }
            Expr::Name(n) => return self.ends(&self.productions[n], text, start),
            Expr::Sequence(items) => {
                let mut at = BTreeSet::from([start]);
                for item in items {
                    at = at.iter().flat_map(|&p| self.ends(item, text, p)).collect();
                    if at.is_empty() {
                        break;
                    }
                }
                return at;
            }
            Expr::Choice(options) => {
                for e in options {
                    out.extend(self.ends(e, text, start));
                }
            }
            Expr::Except(a, b) => {
                let excluded = self.ends(b, text, start);
                return self
                    .ends(a, text, start)
                    .difference(&excluded)
                    .copied()
                    .collect();
            }
            Expr::Optional(e) => {
                out.insert(start);
                out.extend(self.ends(e, text, start));
            }
            Expr::Repeat(e) => {
                // Breadth first over repetitions, each end visited once.
                out.insert(start);
                let mut frontier = BTreeSet::from([start]);
                while !frontier.is_empty() {
                    let next: BTreeSet<usize> = frontier
                        .iter()
                        .flat_map(|&p| self.ends(e, text, p))
                        .filter(|p| !out.contains(p))
                        .collect();
                    out.extend(&next);
                    frontier = next;
                }
            }
            Expr::Times(n, e) => {
                let mut at = BTreeSet::from([start]);
                for _ in 0..*n {
                    at = at.iter().flat_map(|&p| self.ends(e, text, p)).collect();
                }
                return at;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_matches_each_form() {
        let g = Grammar::parse(
            r#"(* a comment *)
            line = word , { " " , word } , [ ";" , { ? any character ? - nl - "!" } ] , nl ;
            word = letter , 2 * digit | "-" ;
            letter = "A" | "B" ;
            digit = "0" | "1" ;
            nl = ? line feed ? ;"#,
        )
        .unwrap();
        assert!(g.matches("line", "A01\n"));
        assert!(g.matches("line", "A01 - B10;note\n"));
        assert!(!g.matches("line", "A0\n"));
        assert!(!g.matches("line", "A012\n"));
        assert!(!g.matches("line", "C01\n"));
        assert!(!g.matches("line", "A01"));
        assert!(!g.matches("line", "A01;a\nb\n"));
        assert!(!g.matches("line", "A01;a!\n"));
        assert!(Grammar::parse("a = b ;").is_err());
        assert!(Grammar::parse("a = \"x\" ").is_err());
    }
}
