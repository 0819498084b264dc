//! [`Bake`] for a model's analyses: each one as written ([`AnalysisSpec`] and its options), and
//! the constants the compiler certified for it, with the region they hold over and how each was
//! bounded ([`Provenance`]).

use proc_macro2::TokenStream;
use quote::quote;
use reachc_core::model::{
    Analysis, AnalysisSpec, AutoFit, Constants, ConstantsParts, Guarantee, Inclusion, InputGain,
    Integrator, MatrixBound, Method, MetricChoice, MetricRegion, NoConstants, Provenance,
    RadiusRule, Rate, Region, Split, Transform, TransformSource,
};

use super::{variant, Bake, Baker};

bake_struct! {
    Analysis { spec, constants }
    AnalysisSpec {
        name,
        method,
        delta,
        horizon,
        step,
        metric,
        radius,
        rate,
        inclusion,
        integrator,
        guarantee,
        transform,
        outputs,
        first_order,
        split,
    }
    Transform { matrix, inverse, frame, source }
}

bake_unit_enum! {
    Method { Contraction, Interval }
    Inclusion { Natural, Jacobian, Mixed }
    Integrator { Validated, Rk4, Euler }
    Guarantee { Uniform, Pointwise }
    MetricRegion { Given, Domain, InitialSet, IdentityAtRun, Map }
}

/// `MetricChoice::Identity`, `MetricChoice::Matrix(..)`, ...
impl Bake for MetricChoice {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            MetricChoice::Identity => quote!(MetricChoice::Identity),
            MetricChoice::Auto => quote!(MetricChoice::Auto),
            MetricChoice::PerState(states) => {
                // Suffixed (`0usize`) in a `vec!`, as generated crates have always written it.
                let states = states.iter().map(|&i| quote!(#i));
                quote!(MetricChoice::PerState(vec![#(#states),*]))
            }
            MetricChoice::Matrix(m) => variant(quote!(MetricChoice::Matrix), m, baker),
        }
    }
}

/// `RadiusRule::Amgf`, `RadiusRule::Paper(eps)` or `RadiusRule::PaperOptimal`.
impl Bake for RadiusRule {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            RadiusRule::Amgf => quote!(RadiusRule::Amgf),
            RadiusRule::Paper(eps) => variant(quote!(RadiusRule::Paper), eps, baker),
            RadiusRule::PaperOptimal => quote!(RadiusRule::PaperOptimal),
        }
    }
}

/// `Rate::Local`, `Rate::Global` or `Rate::Empirical { paths }`.
impl Bake for Rate {
    fn bake(&self, _: &mut Baker<'_>) -> TokenStream {
        match self {
            Rate::Local => quote!(Rate::Local),
            Rate::Global => quote!(Rate::Global),
            // Suffixed (`2000u64`), as generated crates have always written it.
            Rate::Empirical { paths } => quote!(Rate::Empirical { paths: #paths }),
        }
    }
}

/// `TransformSource::Given` or `TransformSource::Auto(..)`.
impl Bake for TransformSource {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            TransformSource::Given => quote!(TransformSource::Given),
            TransformSource::Auto(fit) => variant(quote!(TransformSource::Auto), fit, baker),
        }
    }
}

/// `AutoFit::LogNorm { chosen, identity }` or `AutoFit::NonFiniteJacobian`.
impl Bake for AutoFit {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            AutoFit::LogNorm { chosen, identity } => {
                bake_fields!(baker, AutoFit::LogNorm { chosen, identity })
            }
            AutoFit::NonFiniteJacobian => quote!(AutoFit::NonFiniteJacobian),
        }
    }
}

/// `Split::Off`, `Split::Counts(..)` or `Split::Auto { pieces, seconds }`.
impl Bake for Split {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            Split::Off => quote!(Split::Off),
            Split::Counts(k) => variant(quote!(Split::Counts), k, baker),
            Split::Auto { pieces, seconds } => bake_fields!(baker, Split::Auto { pieces, seconds }),
        }
    }
}

/// `Constants::from_parts(ConstantsParts { .. })`, with the further metrics' constants in `also`
/// and `alternatives`.
impl Bake for Constants {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        let ConstantsParts {
            metric,
            metric_region,
            c,
            sigma,
            rho,
            provenance,
            region,
            also,
            alternatives,
        } = self.clone().into_parts();
        // The nested constants first: the `DATA_k` statics are numbered in this order.
        let also = also.bake(baker);
        let alternatives = alternatives.bake(baker);
        let metric = metric.bake(baker);
        let (c, sigma, rho) = (c.bake(baker), sigma.bake(baker), rho.bake(baker));
        let provenance = provenance.bake(baker);
        let region = region.bake(baker);
        let metric_region = metric_region.bake(baker);
        quote! {
            Constants::from_parts(ConstantsParts {
                metric: #metric,
                metric_region: #metric_region,
                c: #c,
                sigma: #sigma,
                rho: #rho,
                provenance: #provenance,
                region: #region,
                also: #also,
                alternatives: #alternatives,
            })
        }
    }
}

/// `Region { domain, input_box, time }`, a domain or input box equal to the model's written as
/// the clone of `info()`'s binding.
impl Bake for Region {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        let Region {
            domain,
            input_box,
            time,
        } = self;
        let domain = if domain == baker.domain {
            quote!(domain.clone())
        } else {
            domain.bake(baker)
        };
        let input_box = if input_box == baker.input_box {
            quote!(input_box.clone())
        } else {
            input_box.bake(baker)
        };
        let time = time.bake(baker);
        quote!(Region { domain: #domain, input_box: #input_box, time: #time })
    }
}

/// `Provenance::Certified { c, sigma, rho }`, `Provenance::Given`, `Provenance::Map` or
/// `Provenance::Unbounded { why }`.
impl Bake for Provenance {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            Provenance::Certified { c, sigma, rho } => {
                bake_fields!(baker, Provenance::Certified { c, sigma, rho })
            }
            Provenance::Given => quote!(Provenance::Given),
            Provenance::Map => quote!(Provenance::Map),
            Provenance::Unbounded { why } => bake_fields!(baker, Provenance::Unbounded { why }),
        }
    }
}

/// `NoConstants::Unbounded { .. }`, `NoConstants::BadMetric { .. }` or
/// `NoConstants::NotCertified { .. }`.
impl Bake for NoConstants {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            NoConstants::Unbounded { entry, expression } => {
                bake_fields!(baker, NoConstants::Unbounded { entry, expression })
            }
            NoConstants::BadMetric { reason } => {
                bake_fields!(baker, NoConstants::BadMetric { reason })
            }
            NoConstants::NotCertified { constant } => {
                bake_fields!(baker, NoConstants::NotCertified { constant })
            }
        }
    }
}

/// `MatrixBound::Vertices { .. }` or `MatrixBound::Hull { .. }`.
impl Bake for MatrixBound {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            MatrixBound::Vertices {
                count,
                atoms,
                fixed,
            } => bake_fields!(
                baker,
                MatrixBound::Vertices {
                    count,
                    atoms,
                    fixed
                }
            ),
            MatrixBound::Hull {
                atoms,
                fixed,
                vertex_limit,
            } => bake_fields!(
                baker,
                MatrixBound::Hull {
                    atoms,
                    fixed,
                    vertex_limit
                }
            ),
        }
    }
}

/// `InputGain::NoInputs`, `InputGain::Corners(..)` or `InputGain::Columns(..)`.
impl Bake for InputGain {
    fn bake(&self, baker: &mut Baker<'_>) -> TokenStream {
        match self {
            InputGain::NoInputs => quote!(InputGain::NoInputs),
            InputGain::Corners(m) => variant(quote!(InputGain::Corners), m, baker),
            InputGain::Columns(m) => variant(quote!(InputGain::Columns), m, baker),
        }
    }
}
