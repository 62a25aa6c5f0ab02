//! Sweeps: a stage's `matrix` (every combination of the listed values) or `foreach` (the
//! listed points), each point an instance of the stage.

use std::collections::BTreeMap;

use toml::Spanned;

use super::raw::{value_str, RawStage, Source};
use crate::error::Result;

/// One point of a sweep: (name, value) pairs, in the order the instance's name lists them.
pub(super) type Point = Vec<(String, String)>;

/// The sweep points of a stage (`key`: `stages.NAME`): one empty point without a sweep.
pub(super) fn points(st: &RawStage, key: &str, at: &Source) -> Result<Vec<Point>> {
    if let (Some(_), Some(f)) = (&st.matrix, &st.foreach) {
        return Err(at
            .err(
                "a stage has both `matrix` and `foreach`".into(),
                at.line(f.span().start),
                key,
            )
            .expected("one of them"));
    }
    if let Some(mx) = &st.matrix {
        return matrix(mx, key, at);
    }
    if let Some(fe) = &st.foreach {
        return foreach(fe, key, at);
    }
    Ok(vec![vec![]])
}

/// `matrix = { a = [..], b = [..] }`: every combination, the last name varying fastest.
fn matrix(
    mx: &Spanned<BTreeMap<String, Vec<toml::Value>>>,
    key: &str,
    at: &Source,
) -> Result<Vec<Point>> {
    let mut points: Vec<Point> = vec![vec![]];
    let ml = at.line(mx.span().start);
    for (k, vals) in mx.get_ref() {
        if vals.is_empty() {
            return Err(at
                .err(
                    format!("matrix entry `{k}` is an empty list"),
                    ml,
                    &format!("{key}.matrix.{k}"),
                )
                .expected("at least one value"));
        }
        let mut next = Vec::new();
        for p in &points {
            for v in vals {
                let s = value_str(v).ok_or_else(|| {
                    at.err(
                        format!("matrix value of `{k}` is not a scalar"),
                        ml,
                        &format!("{key}.matrix.{k}"),
                    )
                })?;
                let mut q = p.clone();
                q.push((k.clone(), s));
                next.push(q);
            }
        }
        points = next;
    }
    Ok(points)
}

/// `foreach = [{ a = .., b = .. }, ..]`: the points as listed.
fn foreach(
    fe: &Spanned<Vec<BTreeMap<String, toml::Value>>>,
    key: &str,
    at: &Source,
) -> Result<Vec<Point>> {
    let fl = at.line(fe.span().start);
    if fe.get_ref().is_empty() {
        return Err(at
            .err(
                "`foreach` is an empty list".into(),
                fl,
                &format!("{key}.foreach"),
            )
            .expected("at least one item"));
    }
    let mut points = Vec::new();
    for (i, item) in fe.get_ref().iter().enumerate() {
        let mut q = Vec::new();
        for (k, v) in item {
            let s = value_str(v).ok_or_else(|| {
                at.err(
                    format!("foreach item {i}: `{k}` is not a scalar"),
                    fl,
                    &format!("{key}.foreach"),
                )
            })?;
            q.push((k.clone(), s));
        }
        points.push(q);
    }
    Ok(points)
}
