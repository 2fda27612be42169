//! The table `cdyn bench` prints.

use super::*;

/// The table printed on the terminal.
pub fn table(r: &Report) -> String {
    let e = &r.example1;
    let mut out = format!(
        "Example 1, cvsgf_energy, AB-3 ({} runs of {} steps, best of {}):\n",
        e.runs_per_trial, e.steps_per_run, e.trials
    );
    out += &format!("  cdyn (SmallSystem)   {:>8.1} ns/step  overhead {:.2}×\n", e.cdyn_ns_per_step, e.overhead_ratio);
    out += &format!(
        "  cdyn (general Model) {:>8.1} ns/step  overhead {:.2}×\n",
        e.general_ns_per_step, e.general_overhead_ratio
    );
    out += &format!("  hand-written         {:>8.1} ns/step\n", e.handwritten_ns_per_step);
    for (title, runs, exponent) in [
        ("N-link chain, CVSGF + energy, AB-3", &r.chain, r.chain_cost_exponent),
        (
            "spatial chain (rods in Euler parameters, spherical joints), CVSGF + energy, AB-3",
            &r.spatial_chain,
            r.spatial_chain_cost_exponent,
        ),
        ("N-link chain, CVSGF + energy, ABM-4", &r.abm4_chain, r.abm4_chain_cost_exponent),
        ("N-link chain, RATTLE, no control", &r.rattle_chain, r.rattle_chain_cost_exponent),
        (
            "N-link chain, generalized-α, no control",
            &r.generalized_alpha_chain,
            r.generalized_alpha_chain_cost_exponent,
        ),
    ] {
        out += &format!("{title}, h = 1e-3:\n");
        out += &format!("  {:>6} {:>8} {:>12} {:>12} {:>8}\n", "N", "steps", "µs/step", "max|Φ|", "solver");
        for c in runs {
            out += &format!(
                "  {:>6} {:>8} {:>12.2} {:>12.3e} {:>8}\n",
                c.n, c.steps, c.us_per_step, c.max_abs_phi, c.solver
            );
        }
        if let Some(p) = exponent {
            out += &format!("  cost exponent (N ≥ 100): {p:.3}\n");
        }
    }
    if let Some(b) = r.spatial_handwritten.first() {
        out += &format!(
            "spatial chain, cdyn against hand-written (fresh runs of the steps shown, best of {} interleaved trials):\n",
            b.trials
        );
        out += &format!("  {:>6} {:>8} {:>12} {:>14} {:>9}\n", "N", "steps", "cdyn µs", "hand µs", "ratio");
        for b in &r.spatial_handwritten {
            out += &format!(
                "  {:>6} {:>8} {:>12.2} {:>14.2} {:>8.2}×\n",
                b.n, b.steps_per_run, b.cdyn_us_per_step, b.handwritten_us_per_step, b.overhead_ratio
            );
        }
    }
    if let Some(m) = r.methods.first() {
        out += &format!(
            "Methods, AB-3, and RATTLE and generalized-α without control (median of {} interleaved trials; ratio to cvsgf_energy within a trial, median):\n",
            m.trials
        );
    }
    out += &format!(
        "  {:>8} {:>6} {:>7} {:>8} {:>13} {:>12} {:>7} {:>10} {:>10}\n",
        "model", "N", "h", "steps", "method", "µs/step", "ratio", "iter/step", "max|Φ|"
    );
    for m in &r.methods {
        for c in &m.methods {
            let iterations = c.iterations_per_step.map_or("-".into(), |i| format!("{i:.3}"));
            out += &format!(
                "  {:>8} {:>6} {:>7} {:>8} {:>13} {:>12.3} {:>6.2}× {:>10} {:>10.2e}\n",
                m.model,
                m.n,
                m.h,
                m.steps_per_run * m.runs_per_trial,
                c.method,
                c.us_per_step,
                c.ratio_to_cvsgf_energy,
                iterations,
                c.max_abs_phi
            );
        }
    }
    out += "flyball governor (IFToMM A05), no control, best of the trials:\n";
    out += &format!("  {:>18} {:>8} {:>8} {:>12} {:>16}\n", "scheme", "h", "steps", "µs/step", "ms/simulated s");
    for f in &r.flyball {
        out += &format!(
            "  {:>18} {:>8} {:>8} {:>12.2} {:>16.1}\n",
            f.scheme, f.h, f.steps, f.us_per_step, f.ms_per_simulated_second
        );
    }
    out += &format!("allocations per step (max): {}\n", r.max_allocations_per_step);
    out + &realtime_table(&r.realtime)
}

/// The real-time rows: each step timed on its own, and a co-simulation step.
pub fn realtime_table(r: &Realtime) -> String {
    let mut out = "each step timed on its own (real time), µs; wall clock, then this thread's CPU time:\n".to_string();
    out += &format!(
        "  {:<52} {:>7} {:>8} {:>8} {:>9} {:>8} {:>8} {:>8} {:>7} {:>7} {:>6}\n",
        "case", "steps", "median", "99.9%", "max", "cpu med", "cpu 99.9", "cpu max", "at step", "first", "allocs"
    );
    for t in r.step_times.iter().chain(&r.cosimulation) {
        let (w, c) = (&t.wall, &t.cpu);
        out += &format!(
            "  {:<52} {:>7} {:>8.2} {:>8.2} {:>9.1} {:>8.2} {:>8.2} {:>8.1} {:>7} {:>7.1} {:>6}\n",
            t.case,
            t.steps,
            w.median_us,
            w.p999_us,
            w.max_us,
            c.median_us,
            c.p999_us,
            c.max_us,
            c.slowest_step,
            t.first_step_cpu_us,
            t.allocations
        );
    }
    out + &format!("co-simulation step / bare step (CPU medians): {:.2}×\n", r.cosimulation_ratio)
}
