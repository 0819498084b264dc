//! The interpolation tables a generated model reads: which `(table, column)` pairs its methods
//! use ([`Tables::note`], called by the emitter), written once each as `static` arrays
//! ([`Tables::statics`]) named by [`times_ident`] and [`column_ident`].

use std::collections::BTreeMap;

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use super::allow_lints;
use super::bake::{float, int};
use super::docs::doc_attrs;
use crate::model::Model;

/// The `(table, column)` pairs read by the generated code, in a deterministic order.
#[derive(Default)]
pub(super) struct Tables {
    /// Per table, the columns read, in increasing order.
    used: BTreeMap<u32, Vec<u32>>,
}

impl Tables {
    /// Records that the generated code reads `column` of `table`.
    pub(super) fn note(&mut self, table: u32, column: u32) {
        let cols = self.used.entry(table).or_default();
        if !cols.contains(&column) {
            cols.push(column);
            cols.sort_unstable();
        }
    }

    /// The `static` arrays of the tables read, with their sample times, from `model`'s data.
    pub(super) fn statics(&self, model: &Model) -> TokenStream {
        let lints = allow_lints();
        let mut out = TokenStream::new();
        for (&t, cols) in &self.used {
            let table = &model.tables[t as usize];
            let k = int(table.times.len());
            let times_ident = times_ident(t);
            let times = table.times.iter().map(|&v| float(v));
            let doc = doc_attrs(&format!(
                "Sample times of table `{}` ({k} rows).",
                table.name
            ));
            out.extend(quote! {
                #doc
                #lints
                static #times_ident: [f64; #k] = [#(#times),*];
            });
            for &c in cols {
                let ident = column_ident(t, c);
                let values = table.values[c as usize].iter().map(|&v| float(v));
                let doc = doc_attrs(&format!(
                    "Column `{}` of table `{}`, linearly interpolated in time.",
                    table.columns[c as usize], table.name
                ));
                out.extend(quote! {
                    #doc
                    #lints
                    static #ident: [f64; #k] = [#(#values),*];
                });
            }
        }
        out
    }
}

/// The `static` holding the sample times of `table`, `T0_TIMES`.
pub(super) fn times_ident(table: u32) -> Ident {
    format_ident!("T{}_TIMES", table)
}

/// The `static` holding `column` of `table`, `T0_C1`.
pub(super) fn column_ident(table: u32, column: u32) -> Ident {
    format_ident!("T{}_C{}", table, column)
}
