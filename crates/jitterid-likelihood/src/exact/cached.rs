//! One sample's `log p(y)` at many values of `y` (the exact Fisher information integrates each
//! sample's score over a grid of `y`): the parts of [`SampleModel::log_p`] that do not depend
//! on `y`, computed once per sample instead of once per `y`.
//!
//! What does not depend on `y`: the sample's breakpoints within the reach, the signal at the
//! shortcut's Chebyshev nodes (and its total variation there, which decides whether a
//! shortcut is tried) with the signal's gradient channels at them, and the general rule's
//! nodes, weights, signal values and gradient channels. The general rule of `log_p` depends on
//! `y` only through which runs of refined sub-intervals lie farther than the window from `y`
//! and share one 16-point rule; here every sub-interval keeps its own rule (the rule `log_p`
//! itself uses when no node comes near `y`), so one rule serves every `y`. The runs it splits
//! carry at most `e^{−window²/2}` (`e^{−36}` by default) of the peak, so the values differ from
//! `log_p`'s by about that relative to `p(y)`. The shortcut integrates against the jitter's
//! moments by one dot product of the node values with precomputed weights instead of through
//! the Chebyshev coefficients (the same sum reassociated: rounding, `~N·2⁻⁵³` relative), and a
//! node on the boundary of two table segments may take the other segment (the segment searches
//! run in another order), where the table's two pieces agree to its tolerance, `1e-13`.
//! `exact_fisher`'s information agrees with the route through `log_p` to about `1e-12`
//! relative (the test allows `1e-9`).

use super::*;

/// The `y`-independent parts of one sample's likelihood under one [`SampleModel`], each
/// computed on first use.
#[derive(Debug)]
pub(crate) struct SampleCache {
    t: f64,
    /// Whether the gradient channels are wanted.
    gradient: bool,
    local: Vec<f64>,
    /// Whether the shortcut may be tried at all (enabled, no breakpoint within the reach, the
    /// jitter's moments known).
    shortcut: bool,
    narrow: Option<Nodes<CHEB_POINTS>>,
    wide: Option<Nodes<32>>,
    full: Option<Result<(Rule, Vec<f64>), RuleTooLarge>>,
    /// The segment searches' hint, from 0 for every sample (as in `log_p`).
    hint: usize,
}

/// The signal at a shortcut's nodes, `None` when they cannot be formed, and the gradient
/// channels there (empty without a gradient).
#[derive(Debug)]
struct Nodes<const N: usize> {
    nodes: Option<ShortcutNodes<N>>,
    channels: Vec<f64>,
}

/// `c`, unless it is empty (channels that were not computed).
fn non_empty(c: &[f64]) -> Option<&[f64]> {
    (!c.is_empty()).then_some(c)
}

impl SampleCache {
    /// The cache of the sample requested at `t` under `model`, with the gradient channels when
    /// `gradient`.
    pub(crate) fn new<S: Signal + ?Sized>(
        model: &SampleModel<'_, S>,
        t: f64,
        gradient: bool,
    ) -> Self {
        let jp = model.jitter;
        let local = local_breaks(model.breaks, t, jp.lo, jp.hi);
        let shortcut = model.opts.shortcut && local.is_empty() && jp.moments.is_some();
        SampleCache {
            t,
            gradient: gradient && model.signal.grad_channels > 0,
            local,
            shortcut,
            narrow: None,
            wide: None,
            full: None,
            hint: 0,
        }
    }
}

impl<S: Signal + ?Sized> SampleModel<'_, S> {
    /// The nodes of one shortcut with their channels (when the total variation lets the
    /// shortcut be tried).
    fn cached_nodes<const N: usize>(
        &self,
        t: f64,
        tables: &ChebTables<N>,
        max_tv: f64,
        gradient: bool,
        hint: &mut usize,
    ) -> Nodes<N> {
        let nodes = self.shortcut_nodes(t, tables, hint).ok();
        let tried = nodes.as_ref().is_some_and(|n| n.tv <= max_tv * self.sigma);
        let channels = if gradient && tried {
            self.shortcut_channels(t, tables, hint)
        } else {
            Vec::new()
        };
        Nodes { nodes, channels }
    }

    /// [`SampleModel::log_p`] of the sample of `cache` at `y`, reusing (and filling) the
    /// cache; `grad` as there. See the module docs for how the values compare.
    pub(crate) fn log_p_cached(
        &self,
        cache: &mut SampleCache,
        y: f64,
        grad: Option<&mut [f64]>,
        scratch: &mut Scratch,
    ) -> Result<f64, RuleTooLarge> {
        let t = cache.t;
        let len = grad.as_deref().map(|g| g.len());
        if cache.shortcut {
            if let Some(mu) = &self.jitter.moments {
                let narrow_tables = tables16();
                let narrow = cache.narrow.get_or_insert_with(|| {
                    self.cached_nodes(
                        t,
                        narrow_tables,
                        SHORTCUT_TV,
                        cache.gradient,
                        &mut cache.hint,
                    )
                });
                let first = match &narrow.nodes {
                    Some(n) if n.tv <= SHORTCUT_TV * self.sigma => self.shortcut_at(
                        t,
                        y,
                        n,
                        narrow_tables,
                        &mu.narrow,
                        Some(&mu.narrow_weights),
                        len,
                        non_empty(&narrow.channels),
                        scratch,
                    ),
                    _ => Err(f64::INFINITY),
                };
                let v = match first {
                    Err(tv) if tv <= WIDE_SHORTCUT_TV => {
                        let wide_tables = tables32();
                        let wide = cache.wide.get_or_insert_with(|| {
                            self.cached_nodes(
                                t,
                                wide_tables,
                                WIDE_SHORTCUT_TV,
                                cache.gradient,
                                &mut cache.hint,
                            )
                        });
                        match &wide.nodes {
                            Some(n) if n.tv <= WIDE_SHORTCUT_TV * self.sigma => self.shortcut_at(
                                t,
                                y,
                                n,
                                wide_tables,
                                &mu.wide,
                                Some(&mu.wide_weights),
                                len,
                                non_empty(&wide.channels),
                                scratch,
                            ),
                            _ => Err(f64::INFINITY),
                        }
                    }
                    r => r,
                };
                if let Ok(v) = v {
                    if let Some(g) = grad {
                        g.copy_from_slice(&scratch.ch[..g.len()]);
                    }
                    return Ok(v);
                }
            }
        }
        if cache.full.is_none() {
            scratch.sig_hint = cache.hint;
            scratch.pdf_hint = 0;
            let built = self
                .build_rule(t, y, &cache.local, true, scratch)
                .map(|()| {
                    let rule = scratch.rule.clone();
                    let channels = if cache.gradient {
                        let c = 1 + self.signal.grad_channels;
                        let mut out = vec![0.0; rule.tau.len() * c];
                        for (tau, chans) in rule.tau.iter().zip(out.chunks_exact_mut(c)) {
                            self.signal.all(t + tau, chans, &mut scratch.sig_hint);
                        }
                        out
                    } else {
                        Vec::new()
                    };
                    (rule, channels)
                });
            cache.hint = scratch.sig_hint;
            cache.full = Some(built);
        }
        match &cache.full {
            Some(Ok((rule, channels))) => {
                Ok(self.sum(t, y, grad, rule, non_empty(channels), scratch))
            }
            _ => Err(RuleTooLarge),
        }
    }
}
