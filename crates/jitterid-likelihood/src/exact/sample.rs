//! The per-sample quadrature rule and `log p(y_k)` with its gradient: [`SampleModel`]'s
//! methods (see the parent module's docs, "Quadrature" and "Gradient").

use super::*;

impl<S: Signal + ?Sized> SampleModel<'_, S> {
    /// `log p(y)` of a sample requested at `t`, and, when `grad` is given (length
    /// `grad_channels + 1`), `∂ log p/∂θ_signal` followed by `∂ log p/∂σ_v`.
    pub(crate) fn log_p(
        &self,
        t: f64,
        y: f64,
        grad: Option<&mut [f64]>,
        scratch: &mut Scratch,
    ) -> Result<f64, RuleTooLarge> {
        let jp = self.jitter;
        // Segment searches start afresh for every sample: a node on the boundary of two table
        // segments then takes the same segment whichever samples this thread saw before, so a
        // sample's value does not depend on how samples are shared between threads.
        scratch.sig_hint = 0;
        scratch.pdf_hint = 0;
        let local = local_breaks(self.breaks, t, jp.lo, jp.hi);
        if self.opts.shortcut && local.is_empty() {
            if let Some(mu) = &jp.moments {
                let len = grad.as_deref().map(|g| g.len());
                let narrow = tables16();
                // The value and the number of points that gave it.
                let v = match self.shortcut(t, y, narrow, &mu.narrow, SHORTCUT_TV, len, scratch) {
                    Err(tv) if tv <= WIDE_SHORTCUT_TV => {
                        let wide = tables32();
                        self.shortcut(t, y, wide, &mu.wide, WIDE_SHORTCUT_TV, len, scratch)
                            .map(|v| (v, 32))
                    }
                    r => r.map(|v| (v, CHEB_POINTS)),
                };
                if let Ok((v, _points)) = v {
                    #[cfg(test)]
                    tests::note_shortcut(_points);
                    if let Some(g) = grad {
                        g.copy_from_slice(&scratch.ch[..g.len()]);
                    }
                    return Ok(v);
                }
            }
        }
        self.build_rule(t, y, &local, false, scratch)?;
        let rule = std::mem::take(&mut scratch.rule);
        let v = self.sum(t, y, grad, &rule, None, scratch);
        scratch.rule = rule;
        Ok(v)
    }

    /// The range of `s(t + τ)` over the coarse nodes of the jitter (for the Fisher
    /// information's grid in `y`).
    pub(crate) fn signal_range(&self, t: f64) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        let mut hint = 0;
        for c in &self.jitter.coarse {
            for &tau in c.nodes.iter().chain([c.a, c.b].iter()) {
                let s = self.signal.value(t + tau, &mut hint);
                lo = lo.min(s);
                hi = hi.max(s);
            }
        }
        for a in &self.jitter.atoms {
            let s = self.signal.value(t + a.position, &mut hint);
            lo = lo.min(s);
            hi = hi.max(s);
        }
        (lo, hi)
    }

    /// The shortcut on `N` Chebyshev points over the reach (step 5 of the module docs): the
    /// value, or `Err(tv)` with the signal's total variation over the points when the
    /// interpolant of the Gaussian factor is not converged ([`ExactMl::shortcut_tolerance`];
    /// `tv` infinite when it
    /// exceeds `max_tv` and the transform was not taken).
    #[allow(clippy::too_many_arguments)]
    fn shortcut<const N: usize>(
        &self,
        t: f64,
        y: f64,
        tables: &ChebTables<N>,
        mu: &[f64; N],
        max_tv: f64,
        grad_len: Option<usize>,
        scratch: &mut Scratch,
    ) -> Result<f64, f64> {
        let nodes = self.shortcut_nodes(t, tables, &mut scratch.sig_hint)?;
        if !(nodes.tv <= max_tv * self.sigma) {
            return Err(f64::INFINITY);
        }
        self.shortcut_at(t, y, &nodes, tables, mu, None, grad_len, None, scratch)
    }

    /// The signal at the shortcut's `N` Chebyshev nodes over the reach of the sample requested
    /// at `t`, in the basis' order, with its total variation over them; `Err(∞)` if they cannot
    /// be formed.
    pub(super) fn shortcut_nodes<const N: usize>(
        &self,
        t: f64,
        tables: &ChebTables<N>,
        hint: &mut usize,
    ) -> Result<ShortcutNodes<N>, f64> {
        let jp = self.jitter;
        let nodes = tables.basis().nodes();
        let (mid, half) = (0.5 * (jp.lo + jp.hi), 0.5 * (jp.hi - jp.lo));
        // The Chebyshev nodes in increasing order (the basis stores them decreasing).
        let mut taus = [0.0; N];
        for i in 0..N {
            taus[i] = mid + half * nodes[N - 1 - i];
        }
        let mut sv = [0.0; N];
        for (tc, sc) in taus.chunks_exact(16).zip(sv.chunks_exact_mut(16)) {
            // N is 16 or 32, so every chunk has 16 points (the rust-version predates
            // `as_chunks`).
            let (Ok(tc), Ok(sc)) = (<&[f64; 16]>::try_from(tc), <&mut [f64; 16]>::try_from(sc))
            else {
                return Err(f64::INFINITY);
            };
            self.signal.values16(t, tc, sc, hint);
        }
        let tv: f64 = sv.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
        // Back to the basis' order.
        let mut s = [0.0; N];
        for i in 0..N {
            s[i] = sv[N - 1 - i];
        }
        Ok(ShortcutNodes { s, tv })
    }

    /// `[s, ∂s/∂θ…]` at the shortcut's `N` nodes, node-major, in the basis' order (what the
    /// shortcut's gradient reads at every node).
    pub(super) fn shortcut_channels<const N: usize>(
        &self,
        t: f64,
        tables: &ChebTables<N>,
        hint: &mut usize,
    ) -> Vec<f64> {
        let jp = self.jitter;
        let (mid, half) = (0.5 * (jp.lo + jp.hi), 0.5 * (jp.hi - jp.lo));
        let c = 1 + self.signal.grad_channels;
        let mut out = vec![0.0; N * c];
        for (x, chans) in tables.basis().nodes().iter().zip(out.chunks_exact_mut(c)) {
            self.signal.all(t + mid + half * x, chans, hint);
        }
        out
    }

    /// The shortcut at `y` from the signal at its nodes (whose total variation is within the
    /// shortcut's limit), with the nodes' channels from `channels` when given (node-major, as
    /// [`Self::shortcut_channels`]) or evaluated here. With `weights` (the moments' node
    /// weights, [`ChebTables::weights`]) each integral against the moments is one dot product
    /// with the node values instead of the coefficients' (equal up to rounding; only the two
    /// coefficients of the convergence test are formed).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn shortcut_at<const N: usize>(
        &self,
        t: f64,
        y: f64,
        nodes: &ShortcutNodes<N>,
        tables: &ChebTables<N>,
        mu: &[f64; N],
        weights: Option<&[f64; N]>,
        grad_len: Option<usize>,
        channels: Option<&[f64]>,
        scratch: &mut Scratch,
    ) -> Result<f64, f64> {
        let jp = self.jitter;
        let basis_nodes = tables.basis().nodes();
        let (mid, half) = (0.5 * (jp.lo + jp.hi), 0.5 * (jp.hi - jp.lo));
        let sigma = self.sigma;
        let tv = nodes.tv;
        let s = &nodes.s;
        let inv2 = 0.5 / (sigma * sigma);
        let mut e = [0.0; N];
        let mut d0 = f64::INFINITY;
        for (ei, si) in e.iter_mut().zip(s) {
            *ei = y - si;
            d0 = d0.min(*ei * *ei);
        }
        let mut h = [0.0; N];
        for (hi, ei) in h.iter_mut().zip(&e) {
            let q = -(ei * ei - d0) * inv2;
            let v = exp_nonpositive(q);
            *hi = if q >= EXP_FLOOR { v } else { 0.0 };
        }
        let row_dot = |r: &[f64; N], v: &[f64; N]| -> f64 {
            let mut acc = 0.0;
            for i in 0..N {
                acc += v[i] * r[i];
            }
            acc
        };
        let (total, tail) = match weights {
            Some(w) => (
                row_dot(w, &h),
                row_dot(tables.row(N - 2), &h).abs() + row_dot(tables.row(N - 1), &h).abs(),
            ),
            None => {
                let c = tables.coefficients(&h);
                (
                    c.iter().zip(mu).map(|(c, m)| c * m).sum(),
                    c[N - 2].abs() + c[N - 1].abs(),
                )
            }
        };
        if !(total > 0.0) || tail > self.opts.shortcut_tolerance * total {
            return Err(tv / sigma);
        }
        let log_p = -d0 * inv2 + total.ln() - sigma.ln() - HALF_LN_2PI;
        if let Some(len) = grad_len {
            let ns = len - 1;
            scratch.ch.clear();
            scratch.ch.resize(len, 0.0);
            let dot = |v: &[f64; N]| -> f64 {
                match weights {
                    Some(w) => row_dot(w, v) / total,
                    None => {
                        tables
                            .coefficients(v)
                            .iter()
                            .zip(mu)
                            .map(|(c, m)| c * m)
                            .sum::<f64>()
                            / total
                    }
                }
            };
            if ns > 0 {
                let width = 1 + self.signal.grad_channels;
                let mut chans = std::mem::take(&mut scratch.chans);
                chans.resize(width, 0.0);
                // `h e ∂s/∂θ_j` at the nodes, parameter-major.
                let mut g = std::mem::take(&mut scratch.node_gradients);
                g.clear();
                g.resize(ns * N, 0.0);
                for (i, &x) in basis_nodes.iter().enumerate() {
                    let at: &[f64] = match channels {
                        Some(all) => &all[i * width..(i + 1) * width],
                        None => {
                            self.signal
                                .all(t + mid + half * x, &mut chans, &mut scratch.sig_hint);
                            &chans
                        }
                    };
                    for j in 0..ns {
                        g[j * N + i] = h[i] * e[i] * at[1 + j];
                    }
                }
                for j in 0..ns {
                    let mut v = [0.0; N];
                    v.copy_from_slice(&g[j * N..(j + 1) * N]);
                    scratch.ch[j] = dot(&v) / (sigma * sigma);
                }
                scratch.chans = chans;
                scratch.node_gradients = g;
            }
            let mut q = [0.0; N];
            for i in 0..N {
                q[i] = h[i] * e[i] * e[i];
            }
            scratch.ch[ns] = dot(&q) / (sigma * sigma * sigma) - 1.0 / sigma;
        }
        Ok(log_p)
    }

    /// Pushes a 16-point rule on `[a, b]` (density from the table) with the signal values.
    fn push_gl(&self, t: f64, a: f64, b: f64, scratch: &mut Scratch) {
        let (x, w) = gl16();
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        let mut taus = [0.0; 16];
        for i in 0..16 {
            taus[i] = mid + half * x[i];
        }
        let mut p = [0.0; 16];
        self.jitter.pdf16(&taus, &mut p, &mut scratch.pdf_hint);
        let mut sv = [0.0; 16];
        self.signal
            .values16(t, &taus, &mut sv, &mut scratch.sig_hint);
        for i in 0..16 {
            let wi = half * w[i] * p[i];
            if wi > 0.0 {
                scratch.rule.tau.push(taus[i]);
                scratch.rule.w.push(wi);
                scratch.rule.s.push(sv[i]);
            }
        }
    }

    /// One coarse interval `[a, b]` with its 16 nodes (and weights, when shared): either its
    /// rule is pushed (the signal moves little), or it is kept for refinement. Returns whether
    /// a node or gap comes within the window of `y`.
    fn coarse(
        &self,
        t: f64,
        y: f64,
        (a, b): (f64, f64),
        nodes: &[f64; 16],
        weights: Option<&[f64; 16]>,
        scratch: &mut Scratch,
    ) -> bool {
        let res = self.opts.resolution * self.sigma;
        let reach = self.opts.window * self.sigma;
        let mut sv = [0.0; 16];
        self.signal
            .values16(t, nodes, &mut sv, &mut scratch.sig_hint);
        let mut pt = [0.0; 18];
        let mut pv = [0.0; 18];
        pt[1..17].copy_from_slice(nodes);
        pv[1..17].copy_from_slice(&sv);
        // The ends, by linear extrapolation from the outer nodes (within 0.6% of the width).
        pt[0] = a;
        pt[17] = b;
        pv[0] = pv[1] + (pv[1] - pv[2]) * (pt[1] - a) / (pt[2] - pt[1]);
        pv[17] = pv[16] + (pv[16] - pv[15]) * (b - pt[16]) / (pt[16] - pt[15]);
        let tv: f64 = pv.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
        if tv <= res {
            let mut near = false;
            let mut own = [0.0; 16];
            let ws = match weights {
                Some(ws) => ws,
                None => {
                    let (_, gw) = gl16();
                    let half = 0.5 * (b - a);
                    self.jitter.pdf16(nodes, &mut own, &mut scratch.pdf_hint);
                    for i in 0..16 {
                        own[i] *= half * gw[i];
                    }
                    &own
                }
            };
            for i in 0..16 {
                if ws[i] > 0.0 {
                    scratch.rule.tau.push(nodes[i]);
                    scratch.rule.w.push(ws[i]);
                    scratch.rule.s.push(sv[i]);
                    near |= (y - sv[i]).abs() <= reach;
                }
            }
            return near;
        }
        // Steep: margins for the curvature between points, and activity.
        let mut slope = [0.0; 17];
        for j in 0..17 {
            let dt = pt[j + 1] - pt[j];
            slope[j] = if dt > 0.0 {
                (pv[j + 1] - pv[j]) / dt
            } else {
                0.0
            };
        }
        let mut curv = [0.0; 18];
        for j in 1..17 {
            let dt = pt[j + 1] - pt[j - 1];
            curv[j] = if dt > 0.0 {
                (2.0 * (slope[j] - slope[j - 1]) / dt).abs()
            } else {
                0.0
            };
        }
        curv[0] = curv[1];
        curv[17] = curv[16];
        let mut st = Steep {
            t: pt,
            v: pv,
            margin: [0.0; 17],
            active: [false; 17],
        };
        let mut near = false;
        for j in 0..17 {
            let dt = pt[j + 1] - pt[j];
            st.margin[j] = curv[j].max(curv[j + 1]) * dt * dt / 4.0;
            let (lo, hi) = (pv[j].min(pv[j + 1]), pv[j].max(pv[j + 1]));
            st.active[j] = y >= lo - st.margin[j] - reach && y <= hi + st.margin[j] + reach;
            near |= st.active[j];
        }
        scratch.steep.push(st);
        near
    }

    /// The rule of the sample requested at `t` for the value at `y` into `scratch` (`tau`, `w`,
    /// `s`). With `refine_all`, every sub-interval of a steep interval gets its own rule, as
    /// when no node comes near `y`: the rule then does not depend on `y` (it differs from the
    /// rule at `y` only by splitting the runs farther than the window from `y`, which carry at
    /// most `e^{−window²/2}` of the peak).
    pub(super) fn build_rule(
        &self,
        t: f64,
        y: f64,
        local: &[f64],
        refine_all: bool,
        scratch: &mut Scratch,
    ) -> Result<(), RuleTooLarge> {
        let jp = self.jitter;
        let res = self.opts.resolution * self.sigma;
        scratch.rule.tau.clear();
        scratch.rule.w.clear();
        scratch.rule.s.clear();
        scratch.steep.clear();
        let mut near = false;
        if local.is_empty() {
            for c in &jp.coarse {
                near |= self.coarse(t, y, (c.a, c.b), &c.nodes, Some(&c.weights), scratch);
            }
        } else {
            let (x, _) = gl16();
            let mut cut = std::mem::take(&mut scratch.cut);
            cut.clear();
            for c in &jp.coarse {
                let mut a = c.a;
                for &bk in local.iter().filter(|&&bk| bk > c.a && bk < c.b) {
                    cut.push((a, bk));
                    a = bk;
                }
                cut.push((a, c.b));
            }
            for &(a, b) in &cut {
                let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
                let mut nodes = [0.0; 16];
                for i in 0..16 {
                    nodes[i] = mid + half * x[i];
                }
                near |= self.coarse(t, y, (a, b), &nodes, None, scratch);
            }
            scratch.cut = cut;
        }
        // Refine the steep intervals.
        let steep = std::mem::take(&mut scratch.steep);
        for st in &steep {
            self.refine(t, st, refine_all || !near, res, scratch);
            if scratch.rule.tau.len() > MAX_SAMPLE_NODES {
                scratch.steep = steep;
                return Err(RuleTooLarge);
            }
        }
        scratch.steep = steep;
        for atom in &jp.atoms {
            scratch.rule.tau.push(atom.position);
            scratch.rule.w.push(atom.mass);
            let s = self.signal.value(t + atom.position, &mut scratch.sig_hint);
            scratch.rule.s.push(s);
        }
        Ok(())
    }

    /// Splits a steep interval into sub-intervals of signal range about `res` and pushes the
    /// rules (see the module docs). `all_active` refines everything.
    fn refine(&self, t: f64, st: &Steep, all_active: bool, res: f64, scratch: &mut Scratch) {
        let mut tv = [0.0; 17];
        let mut cum = [0.0; 18];
        for j in 0..17 {
            tv[j] = (st.v[j + 1] - st.v[j]).abs() + 2.0 * st.margin[j];
            cum[j + 1] = cum[j] + tv[j];
        }
        let total = cum[17];
        let m = ((total / res).ceil() as usize).clamp(1, MAX_SUBDIVISIONS);
        // Boundary i of m, by inverting the piecewise-linear cumulative variation.
        let boundary = |i: usize, gap: &mut usize| -> f64 {
            if i == 0 {
                return st.t[0];
            }
            if i == m {
                *gap = 16;
                return st.t[17];
            }
            let c = total * i as f64 / m as f64;
            while *gap < 16 && cum[*gap + 1] < c {
                *gap += 1;
            }
            let j = *gap;
            let frac = if tv[j] > 0.0 {
                ((c - cum[j]) / tv[j]).clamp(0.0, 1.0)
            } else {
                0.0
            };
            st.t[j] + frac * (st.t[j + 1] - st.t[j])
        };
        let mut gap = 0usize;
        let mut a = boundary(0, &mut gap);
        let mut run_start: Option<f64> = None;
        for i in 0..m {
            let first_gap = gap;
            let b = boundary(i + 1, &mut gap);
            // [a, b] overlaps the gaps first_gap..=gap.
            let active = all_active || st.active[first_gap..=gap].iter().any(|&x| x);
            if active {
                if let Some(r) = run_start.take() {
                    self.push_gl(t, r, a, scratch);
                }
                self.push_gl(t, a, b, scratch);
            } else if run_start.is_none() {
                run_start = Some(a);
            }
            a = b;
        }
        if let Some(r) = run_start {
            self.push_gl(t, r, a, scratch);
        }
    }

    /// Log-sum-exp of `rule`, with the gradient; the signal's channels at the nodes from
    /// `channels` when given (node-major, one row per node of `rule`), else evaluated here.
    pub(super) fn sum(
        &self,
        t: f64,
        y: f64,
        grad: Option<&mut [f64]>,
        rule: &Rule,
        channels: Option<&[f64]>,
        scratch: &mut Scratch,
    ) -> f64 {
        let sigma = self.sigma;
        let inv2 = 0.5 / (sigma * sigma);
        let lmax = max_exponent(&rule.s, y, inv2);
        if !lmax.is_finite() {
            if let Some(g) = grad {
                g.fill(f64::NAN);
            }
            return f64::NEG_INFINITY;
        }
        scratch.terms.clear();
        scratch.terms.resize(rule.s.len(), 0.0);
        let mut total = weighted_terms(&rule.s, &rule.w, (y, inv2, lmax), &mut scratch.terms);
        let mut shift = lmax;
        let mut use_logs = false;
        if !(total > 1e-280) {
            // The largest exponent sits on negligible weights: include the weights' logs.
            use_logs = true;
            shift = f64::NEG_INFINITY;
            for (&s, &w) in rule.s.iter().zip(&rule.w) {
                let e = y - s;
                shift = shift.max(w.ln() - e * e * inv2);
            }
            total = 0.0;
            for (&s, &w) in rule.s.iter().zip(&rule.w) {
                let e = y - s;
                total += (w.ln() - e * e * inv2 - shift).exp();
            }
        }
        let log_p = shift + total.ln() - sigma.ln() - HALF_LN_2PI;
        if let Some(g) = grad {
            let ns = g.len() - 1;
            g.fill(0.0);
            let width = 1 + self.signal.grad_channels;
            let mut chans = std::mem::take(&mut scratch.chans);
            chans.resize(width, 0.0);
            for i in 0..rule.s.len() {
                let e = y - rule.s[i];
                let r = if use_logs {
                    (rule.w[i].ln() - e * e * inv2 - shift).exp() / total
                } else {
                    scratch.terms[i] / total
                };
                if r < 1e-300 {
                    continue;
                }
                g[ns] += r * e * e;
                if ns > 0 {
                    let at: &[f64] = match channels {
                        Some(all) => &all[i * width..(i + 1) * width],
                        None => {
                            self.signal
                                .all(t + rule.tau[i], &mut chans, &mut scratch.sig_hint);
                            &chans
                        }
                    };
                    for j in 0..ns {
                        g[j] += r * e * at[1 + j];
                    }
                }
            }
            scratch.chans = chans;
            let s2 = sigma * sigma;
            for gj in g[..ns].iter_mut() {
                *gj /= s2;
            }
            g[ns] = g[ns] / (s2 * sigma) - 1.0 / sigma;
        }
        log_p
    }
}
