//! [`Bake`] for the sets of a model: its initial set, its unsafe and goal sets, their shapes and
//! the numbers of them that move with time (method.md 8.15); and its [`Time`].

use proc_macro2::TokenStream;
use quote::quote;
use reachc_core::model::{Ball, GoalSet, InitialSet, Moving, Slot, Time, UnsafeSet, UnsafeShape};

use super::{variant, Bake, Baker};

bake_struct! {
    InitialSet { boxes, balls }
    Ball { states, center, radius, metric }
    UnsafeSet { name, shape, moving }
    GoalSet { name, parts, moving, window, stay }
    Moving { part, slot, number }
}

/// `UnsafeShape::Box(..)`, `UnsafeShape::Ball { .. }` or `UnsafeShape::HalfSpace { .. }`.
impl Bake for UnsafeShape {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            UnsafeShape::Box(sides) => variant(quote!(UnsafeShape::Box), sides, baker),
            UnsafeShape::Ball {
                states,
                center,
                radius,
            } => bake_fields!(
                baker,
                UnsafeShape::Ball {
                    states,
                    center,
                    radius
                }
            ),
            UnsafeShape::HalfSpace { normal, offset } => {
                bake_fields!(baker, UnsafeShape::HalfSpace { normal, offset })
            }
        }
    }
}

/// `Slot::Offset`, `Slot::Lo(k)`, ...
impl Bake for Slot {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            Slot::Offset => quote!(Slot::Offset),
            Slot::Lo(k) => variant(quote!(Slot::Lo), k, baker),
            Slot::Hi(k) => variant(quote!(Slot::Hi), k, baker),
            Slot::Center(k) => variant(quote!(Slot::Center), k, baker),
            Slot::Radius => quote!(Slot::Radius),
        }
    }
}

/// `Time::Continuous` or `Time::Discrete { period }`.
impl Bake for Time {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            Time::Continuous => quote!(Time::Continuous),
            Time::Discrete { period } => bake_fields!(baker, Time::Discrete { period }),
        }
    }
}
