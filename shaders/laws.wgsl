// Contact laws (src/law/*.rs), line for line in f32. Coefficients come from the host's
// f64 ContactLaw through Params.

struct ContactInput {
    delta: f32,
    r: f32,
    sigma: f32,
    delta_dot: f32,
    v_t: f32,
    m12: f32,
    mass: f32,
    history: f32,
    dt: f32,
    // The spring-dashpot law's pair of materials (slot of Params.pair_law) and the
    // contact's effective mass, a fixed partner or a wall infinitely heavy
    // (src/law/restitution.rs); the other laws ignore them.
    m_eff: f32,
    pair: u32,
    // The continuous law's other readings of v_t (paper 001 eq. 4, 6): the centres'
    // relative velocity along t and the sum of the spins; the other laws ignore them.
    v_centres: f32,
    spin: f32,
};

struct ContactOutput {
    f_n: f32,
    f_t: f32,
    history: f32,
    energy: f32,
    // The lever of f_t in both torques where the law sets one (paper 001 eq. 13: the
    // centre distance); 0: the contact point's arms.
    lever: f32,
};

fn pow_pos(x: f32, y: f32) -> f32 {
    if (x <= 0.0) { return 0.0; }
    return pow(x, y);
}

// f_el = k_n delta0 (delta/delta0)^nu, paper 000 eq. 2.
fn elastic_force(k_n: f32, delta: f32) -> f32 {
    if (params.nu == 1.0) { return k_n * delta; }
    return k_n * params.delta0 * pow_pos(delta / params.delta0, params.nu);
}

// f_diss = gamma_n delta_dot (delta/delta0)^psi, paper 000 eq. 3.
fn dissipative_force(gamma_n: f32, delta: f32, delta_dot: f32) -> f32 {
    if (params.psi == 0.0) { return gamma_n * delta_dot; }
    return gamma_n * delta_dot * pow_pos(delta / params.delta0, params.psi);
}

fn elastic_energy(k_n: f32, delta: f32) -> f32 {
    let nu = params.nu;
    return k_n * params.delta0 * params.delta0
        * pow_pos(delta / params.delta0, nu + 1.0) / (nu + 1.0);
}

// The same with the damping coefficient given (src/law/tangential.rs `coulomb_spring`).
fn damped_coulomb_spring(xi0: f32, v_t: f32, dt: f32, f_n: f32, gamma_t: f32) -> vec2<f32> {
    return coulomb_spring_with(xi0, v_t, dt, f_n, params.k_t, gamma_t, params.mu);
}

// Coulomb-capped spring, paper 000 eq. 4-5, with every coefficient given: returns
// (f_t, new xi).
fn coulomb_spring_with(xi0: f32, v_t: f32, dt: f32, f_n: f32, k_t: f32, gamma_t: f32,
                       mu: f32) -> vec2<f32> {
    let xi = xi0 + v_t * dt;
    let trial = -k_t * xi - gamma_t * v_t;
    let cap = mu * f_n;
    if (abs(trial) <= cap) { return vec2<f32>(trial, xi); }
    let f_t = select(-cap, cap, trial >= 0.0);
    var xs = 0.0;
    if (k_t > 0.0) { xs = -f_t / k_t; }
    return vec2<f32>(f_t, xs);
}

// The spring-dashpot's coefficients of a contact (src/law/spring_dashpot.rs
// `coefficients`): its pair's, times its effective mass in the material form.
fn spring_dashpot(c: ContactInput) -> ContactOutput {
    var m = 1.0;
    if (params.per_mass != 0u) { m = c.m_eff; }
    let k = params.pair_law[2u * c.pair] * m;
    let mu = params.pair_law[2u * c.pair + 1u].x;
    let f_el = elastic_force(k.x, c.delta);
    let f_diss = dissipative_force(k.y, c.delta, c.delta_dot);
    var f_n = f_el + f_diss;
    if (params.clamp != 0u) { f_n = max(f_n, 0.0); }
    let t = coulomb_spring_with(c.history, c.v_t, c.dt, f_n, k.z, k.w, mu);
    let energy = elastic_energy(k.x, c.delta) + 0.5 * k.z * t.y * t.y;
    return ContactOutput(f_n, t.x, t.y, energy, 0.0);
}

// Tapered friction, paper 001 eq. 5, and its stiffness, eq. 7.
fn tapered_friction(delta_f: f32, delta_max: f32, mu_f_n: f32) -> f32 {
    if (delta_max <= 0.0) { return 0.0; }
    let u = min(abs(delta_f) / delta_max, 1.0);
    return mu_f_n * (1.0 - pow_pos(1.0 - u, 1.5));
}

fn tapered_stiffness(delta_f: f32, delta_max: f32, mu_f_n: f32) -> f32 {
    if (delta_max <= 0.0) { return 0.0; }
    let u = min(abs(delta_f) / delta_max, 1.0);
    return 1.5 * mu_f_n / delta_max * sqrt(1.0 - u);
}

fn tapered_energy(delta_f: f32, delta_max: f32, mu_f_n: f32) -> f32 {
    if (delta_max <= 0.0) { return 0.0; }
    let x = min(abs(delta_f), delta_max);
    return mu_f_n * (x + 0.4 * delta_max * (pow_pos(1.0 - x / delta_max, 2.5) - 1.0));
}

// delta = sigma - r, taken from the geometry where it is exact (position.wgsl).
fn continuous_force(m: f32, sigma: f32, r: f32, delta: f32) -> f32 {
    if (params.elastic == 0u) {
        if (r < params.r0 * sigma) { return m * params.g_scale * pow(sigma / r, params.n_exp + 1.0); }
    } else if (r < sigma) {
        return params.hooke_k * m * params.g_scale / sigma * delta;
    }
    return 0.0;
}

fn continuous_stiffness(m: f32, sigma: f32, r: f32) -> f32 {
    if (params.elastic == 0u) {
        if (r < params.r0 * sigma) {
            return (params.n_exp + 1.0) * m * params.g_scale / sigma * pow(sigma / r, params.n_exp + 2.0);
        }
    } else if (r < sigma) {
        return params.hooke_k * m * params.g_scale / sigma;
    }
    return 0.0;
}

fn continuous_energy(m: f32, sigma: f32, r: f32, delta: f32) -> f32 {
    if (params.elastic == 0u) {
        if (r < params.r0 * sigma) {
            let n = params.n_exp;
            return m * params.g_scale * sigma / n * (pow(sigma / r, n) - pow(1.0 / params.r0, n));
        }
    } else if (r < sigma) {
        return 0.5 * params.hooke_k * m * params.g_scale / sigma * delta * delta;
    }
    return 0.0;
}

// Continuous interaction with tapered friction, paper 001 eq. 3-8.
fn continuous(c: ContactInput) -> ContactOutput {
    let m = c.mass;
    let f_e = continuous_force(m, c.sigma, c.r, c.delta);
    let k = continuous_stiffness(m, c.sigma, c.r);
    let c_n = params.damping_fraction * 2.0 * sqrt(m * k);       // eq. 3, no clamp
    var f_n = f_e + c_n * c.delta_dot;
    if (params.clamp != 0u) { f_n = max(f_n, 0.0); }
    let delta_n = max(params.r0 * c.sigma - c.r, 0.0);
    let delta_max = params.alpha * params.mu * delta_n;
    // Eq. 6: the spins on the centre distance as written, or the surfaces' slip.
    var slip = c.v_centres - c.spin * c.r;
    if ((params.reading & READING_CONTACT_ARM) != 0u) { slip = c.v_t; }
    var delta_f = c.history + slip * c.dt;
    if ((params.reading & READING_SLIDE) != 0u) {
        let bound = max(delta_max, abs(c.history));
        delta_f = clamp(delta_f, -bound, bound);
    } else if ((params.reading & READING_ACCUMULATE) == 0u) {
        delta_f = clamp(delta_f, -delta_max, delta_max);
    }
    let mu_f_e = params.mu * f_e;
    let spring = tapered_friction(delta_f, delta_max, mu_f_e);
    let k_t = tapered_stiffness(delta_f, delta_max, mu_f_e);
    let c_t = params.damping_fraction * 2.0 * sqrt(m * k_t);     // eq. 8
    // Eq. 4: on the centres' velocity as written, or on the surfaces' slip.
    var v_damped = c.v_centres;
    if ((params.reading & READING_SLIP_DAMPING) != 0u) { v_damped = c.v_t; }
    var f_t = -spring * sign(delta_f) - c_t * v_damped;
    if (delta_f == 0.0) { f_t = -c_t * v_damped; }
    let energy = continuous_energy(m, c.sigma, c.r, c.delta) + tapered_energy(delta_f, delta_max, mu_f_e);
    // Eq. 13: the torques on the lever eq. 6 gives the spins.
    var lever = c.r;
    if ((params.reading & READING_CONTACT_ARM) != 0u) { lever = 0.0; }
    return ContactOutput(f_n, f_t, delta_f, energy, lever);
}

// Overlap-area law of polygons, paper 000 eq. 6-7 (src/law/overlap_area.rs): delta is
// A/l, r the depth A/L; eta_n and eta_t arrive in gamma_n and gamma_t.
// The coefficients come from the pair's slot: (k_n, eta_n, k_t, eta_t) and mu, k per
// unit of the effective mass in the material form (src/law/overlap_area.rs `evaluate`).
fn overlap_area(c: ContactInput) -> ContactOutput {
    let pl = params.pair_law[2u * c.pair];
    let mu = params.pair_law[2u * c.pair + 1u].x;
    var m = c.m12;
    var k_n = pl.x;
    var k_t = pl.z;
    if (params.per_mass != 0u) {
        m = c.m_eff;
        k_n = pl.x * m;
        k_t = pl.z * m;
    }
    let gamma_n = pl.y * sqrt(m * k_n);
    let gamma_t = pl.w * sqrt(m * k_t);
    let f_el = k_n * c.delta;
    let f_n = max(f_el + gamma_n * c.delta_dot, 0.0);
    let xi = c.history + c.v_t * c.dt;
    let trial = -k_t * xi - gamma_t * c.v_t;
    let cap = mu * f_n;
    var f_t = trial;
    var xs = xi;
    if (abs(trial) > cap) {
        f_t = select(-cap, cap, trial >= 0.0);
        xs = 0.0;
        if (k_t > 0.0) { xs = -f_t / k_t; }
    }
    let energy = 0.5 * f_el * c.r + 0.5 * k_t * xs * xs;
    return ContactOutput(f_n, f_t, xs, energy, 0.0);
}

// Paper 004's law (src/law/hertz_cohesive.rs): F_N = k^N delta^{3/2} + gamma^N m12
// delta_dot, clamped at 0, a Coulomb-capped spring damped by gamma^T m12, and a constant
// pull F_c = Bo g m while the gap is below d_c (delta > -d_c; `c.mass` is m).
fn hertz_cohesive(c: ContactInput) -> ContactOutput {
    if (!(c.delta > -params.d_c)) { return ContactOutput(0.0, 0.0, 0.0, 0.0, 0.0); }
    let f_c = params.bond_g * c.mass;
    var f_rep = 0.0;
    var elastic = 0.0;
    var t = vec2<f32>(0.0);
    if (c.delta > 0.0) {
        let d32 = c.delta * sqrt(c.delta);
        f_rep = max(params.k_n * d32 + params.gamma_n * c.m12 * c.delta_dot, 0.0);
        elastic = 0.4 * params.k_n * d32 * c.delta;
        t = damped_coulomb_spring(c.history, c.v_t, c.dt, f_rep, params.gamma_t * c.m12);
    }
    let energy = elastic + 0.5 * params.k_t * t.y * t.y - f_c * (c.delta + params.d_c);
    return ContactOutput(f_rep - f_c, t.x, t.y, energy, 0.0);
}

// The law a pipeline is built for (`Build::law`, src/gpu/kernels.rs). The contact
// kernels get the scene's, so the other laws are compiled out of them (fewer registers
// and no branch on the law per contact). LAW_ANY, the default (tests of single
// functions), reads Params.law at run time.
const LAW_ANY: u32 = 0xFFFFFFFFu;
override LAW: u32 = LAW_ANY;

fn evaluate(c: ContactInput) -> ContactOutput {
    let law = select(LAW, params.law, LAW == LAW_ANY);
    if (law == LAW_SPRING_DASHPOT) { return spring_dashpot(c); }
    if (law == LAW_AREA) { return overlap_area(c); }
    if (law == LAW_HERTZ) { return hertz_cohesive(c); }
    return continuous(c);
}
