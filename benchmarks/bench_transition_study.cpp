// Studies behind the sparse path's decisions (part of bench_stackbeam; figures and the commands
// that made them: docs/performance.md): TransitionStudy (decisions 036-045) and PathChoice
// (decision 050).
#include "bench_support.hpp"

using namespace stackbeam;
using namespace stackbeam::bench;

/// A study of the transition steps (docs/decisions/036, 037, 038): ElasticRuns' figures on the
/// graduated (stack 1) or identical (stack 2) 10-leaf spring with elastic interfaces, or the same
/// meshes bonded with rigid interfaces (stacks 3 / 4: the targets' reference), with the
/// transition method of decision 037 in part or whole (`way`, a bit mask of its changes, each
/// bit the Switches field at its default, else the way before: 1 newton_passes, 2
/// smoothing_from_rest, 4 first_pass_start, 8 creep_limit, 16 nonmonotone_memory; 29 the
/// default (smoothing_from_rest is off), 0 the way before; bit 32 decision 038's routes,
/// Switches::fixed_pattern 4 and schur_fresh_max_rows 200, else 2 and none; 61 every default;
/// bit 64 decision 041's homotopy from rest off, Switches::rest_path_violations 0, so 125 is
/// 61 the way before 041) and, with trace 1, the statistics of
/// every transition step (SparsePathTuning::observer, trace.hpp) printed to stderr: mode changes per Newton
/// iteration, pairs back in a mode they had left, the distances of the start, a predicted start
/// and the Newton method's first modes to the step's final modes, how the semismooth method
/// ended; per phase and route the mode solver's calls and their CPU time (decision 038).
/// args: elements per half leaf, stack, simulated ms, way, trace, schur (> 0:
/// SparsePathTuning::schur_max_rows; 0 its default), fixed (Switches::fixed_pattern; -1 its
/// default), path (the homotopy, docs/decisions/040: 0 off, the way before; > 0 on with a
/// new base past that many changed rows, Switches::path_rebase_rows, 48 the default; -1 on
/// without new bases), hits (Switches::path_max_start_hits; -1 its default 500, 0 no
/// limit), repair (docs/decisions/042; -1 the defaults, else a bit mask of its changes, each bit
/// the Switches field at its default, else the way before: 1 path_clamp_slip, 2
/// path_max_pair_switches, 4 path_fold_ends, 8 path_keep_base (decision 045); 0 the way before
/// 042, 7 the way before 045). Each run's answer at its end (w, dissipated energy, |z|) goes to
/// stderr to 17 digits, with the trace the homotopy's counts.
void TransitionStudy(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int stack = static_cast<int>(state.range(1));
    ModelSpec spec = stack == 1 || stack == 3 ? graduated_stack(elements, 10) : paper_stack(PaperCase::friction, elements, 10);
    for (auto& f : spec.interfaces) {
        if (stack <= 2) f.contact = InterfaceContact::elastic;
        else f.law = InterfaceLaw::bonded;
    }
    const double t_sim = 1e-3 * static_cast<double>(state.range(2));
    const int way = static_cast<int>(state.range(3));
    detail::sparse::TransitionTrace trace;
    const SparsePathMethods now;
    SparsePathMethods sw = SparsePathMethods::before_037();
    if ((way & 1) != 0) sw.newton_passes = now.newton_passes;
    if ((way & 2) != 0) sw.smoothing_from_rest = true;
    if ((way & 4) != 0) sw.first_pass_start = now.first_pass_start;
    if ((way & 8) != 0) sw.creep_limit = now.creep_limit;
    if ((way & 16) != 0) sw.nonmonotone_memory = now.nonmonotone_memory;
    if ((way & 32) == 0) {  // decision 038's routes off: the fixed pattern's KLU, no fresh-LU limit
        sw.fixed_pattern = 2;
        sw.schur_fresh_max_rows = -1;
    }
    if (state.range(6) >= 0) sw.fixed_pattern = static_cast<int>(state.range(6));
    const int path_arg = static_cast<int>(state.range(7));
    sw.path_following = path_arg != 0 ? 1 : 0;
    if (path_arg != 0) sw.path_rebase_rows = path_arg > 0 ? path_arg : 0;
    if (state.range(8) >= 0) sw.path_max_start_hits = static_cast<int>(state.range(8));
    if ((way & 64) != 0) sw.rest_path_violations = 0;  // decision 041's homotopy from rest off
    if (state.range(9) >= 0) {  // decision 042's repairs of the homotopy, else the way before
        sw.path_clamp_slip = (state.range(9) & 1) != 0;
        sw.path_max_pair_switches = (state.range(9) & 2) != 0 ? now.path_max_pair_switches : 6;
        sw.path_fold_ends = (state.range(9) & 4) != 0 ? now.path_fold_ends : true;
        sw.path_keep_base = (state.range(9) & 8) != 0 ? now.path_keep_base : 0;  // decision 045
    }
    SimulationOptions so;
    so.sparse_tuning.methods = sw;
    if (state.range(4) == 1) so.sparse_tuning.observer = &trace;  // the trace argument
    so.t_end_s = t_sim;
    so.stop_on_nonconvergence = false;
    if (state.range(5) > 0) so.sparse_tuning.schur_max_rows = static_cast<int>(state.range(5));
    ElasticFigures fig;
    for (auto _ : state) {
        trace.steps.clear();
        fig.run(spec, so);
    }
    fig.put(state, t_sim);
    std::fprintf(stderr, "# TransitionStudy el:%d stack:%d ms:%d way:%d path:%d answer: w %.17g m, dissipated %.17g J, |z| %.17g\n",
                 elements, stack, static_cast<int>(state.range(2)), way, path_arg, fig.final_w_m, fig.dissipated_j,
                 fig.z_norm);
    if (state.range(4) != 1) return;
    // the homotopy (Switches::path_following, docs/decisions/040): the steps it ran on, those
    // it settled (its modes confirmed), its breakpoints, columns (and the multi-column solves
    // that made them), base factorisations, pairs evaluated exactly per pair test, the
    // confirming passes' solves, and the fallbacks by reason
    {
        double runs = 0, settled = 0, bp = 0, cols = 0, blocks = 0, fact = 0, conf = 0, rebases = 0, evals = 0, tests = 0;
        double col_s = 0, base_s = 0, all_s = 0, kept = 0, start_rows = 0, end_rows = 0;
        std::map<int, int> start_hist, end_hist;  // rows by bins of 8
        std::map<int, int> path_ends;
        for (const auto& t : trace.steps) {
            if (t.path.end == 0) continue;
            ++runs;
            settled += t.path_confirmed;
            bp += t.path.breakpoints;
            cols += t.path.columns;
            blocks += t.path.column_blocks;
            fact += t.path.factorizations;
            rebases += t.path.rebases;
            conf += t.path_confirm_solves;
            evals += static_cast<double>(t.path.evaluations);
            tests += static_cast<double>(t.path.pair_tests);
            col_s += t.path.column_s;
            base_s += t.path.base_s;
            all_s += t.path.total_s;
            end_rows += t.path.end_rows;
            ++end_hist[t.path.end_rows / 8 * 8];
            if (t.path.kept_base) {
                ++kept;
                start_rows += t.path.start_rows;
                ++start_hist[t.path.start_rows / 8 * 8];
            }
            ++path_ends[static_cast<int>(t.path.end) * 10 + (t.path_confirmed ? 0 : 1)];
        }
        state.counters["path_runs"] = runs;
        state.counters["path_fallbacks"] = runs - settled;
        state.counters["breakpoints_per_path"] = runs > 0 ? bp / runs : 0.0;
        state.counters["columns_per_path"] = runs > 0 ? cols / runs : 0.0;
        if (runs > 0) {
            std::fprintf(stderr, "# path: %g runs, %g settled; per run %.2f breakpoints, %.2f columns in %.2f solves, %.2f factorisations (%.2f new bases), %.2f confirming solves; pairs evaluated %.3f of tested; ends (10 x end + unconfirmed):",
                         runs, settled, bp / runs, cols / runs, blocks / runs, fact / runs, rebases / runs, conf / runs,
                         tests > 0 ? evals / tests : 0.0);
            std::fprintf(stderr, " CPU ms per run: %.2f (columns %.2f, bases %.2f);", 1e3 * all_s / runs,
                         1e3 * col_s / runs, 1e3 * base_s / runs);
            for (const auto& e : path_ends) std::fprintf(stderr, " [%d]=%d", e.first, e.second);
            // decision 045: the base kept from the run before, the rows the start modes differ from
            // it, the rows the end modes differ from the last base (by bins of 8 rows: first row)
            std::fprintf(stderr, " kept base %g runs, start rows %.1f, end rows %.1f; start rows hist:", kept,
                         kept > 0 ? start_rows / kept : 0.0, end_rows / runs);
            for (const auto& e : start_hist) std::fprintf(stderr, " %d:%d", e.first, e.second);
            std::fprintf(stderr, "; end rows hist:");
            for (const auto& e : end_hist) std::fprintf(stderr, " %d:%d", e.first, e.second);
            std::fprintf(stderr, " (1 reached, 2 n/a, 3 singular, 4 rows, 5 breakpoints, 6 stalled, 7 folded, 8 cycled, 9 singular modes, 10 start hits)\n");
            // per run: the start modes' failing conditions (the first ratio test's hits), its
            // breakpoints, columns, CPU ms, settled
            std::fprintf(stderr, "# path runs: start hits / breakpoints / columns / CPU ms / settled:");
            for (const auto& t : trace.steps)
                if (t.path.end != 0)
                    std::fprintf(stderr, " %d/%d/%d/%.1f/%d", t.path.start_hits, t.path.breakpoints, t.path.columns,
                                 1e3 * t.path.total_s, t.path_confirmed ? 1 : 0);
            std::fprintf(stderr, "\n");
        }
    }
    // the statistics over the steps with a Newton method (and over those the passes settled)
    const auto& steps = trace.steps;
    std::fprintf(stderr, "\n# TransitionStudy el:%d stack:%d ms:%d way:%d: %zu solves\n", elements, stack,
                 static_cast<int>(state.range(2)), way, steps.size());
    std::fprintf(stderr, "# step solves fact passes settled newton end conf confsolves smooth ok | start(n,t) pred(n,t) first(n,t) passes(n,t) | pairs changed maxch | per iteration: n+t changes/returns/step/violations\n");
    struct Sum { double n = 0, v = 0; void add(double x) { n += 1; v += x; } double mean() const { return n > 0 ? v / n : 0.0; } };
    Sum newton_its, pass_solves, confirm, smooth, solves, start_n, start_t, pred_n, pred_t, first_n, first_t, passes_n,
        passes_t, changed, maxch, set_start_n, set_start_t, set_pred_n, set_pred_t, pairs_sum, returns;
    std::map<int, int> ends;
    std::vector<Sum> it_changes(20), it_returns(20), it_full(20), it_viol(20);
    int idx = 0, newton_steps = 0, settled_steps = 0, smoothing_steps = 0, smoothing_ok = 0, revisit_steps = 0;
    for (const auto& t : steps) {
        ++idx;
        if (t.solves == 0) continue;
        std::fprintf(stderr, "%4d %3d %3d %2d %d %2zu %d %d %d %3d %d | %4d %4d  %4d %4d  %4d %4d  %4d %4d | %4d %4d %2d |", idx,
                     t.solves, t.factorizations, t.pass_solves, t.passes_settled, t.iterations.size(), t.newton_end,
                     t.newton_confirmed, t.confirm_solves, t.smoothing_iterations, t.smoothing_ok, t.start_n, t.start_t,
                     t.pred_n, t.pred_t, t.first_n, t.first_t, t.passes_n, t.passes_t, t.pairs, t.pairs_changed,
                     t.max_changes_per_pair);
        for (const auto& it : t.iterations)
            std::fprintf(stderr, " %d/%d/%.2g/%d", it.n_changes + it.t_changes, it.returns, it.step, it.violations);
        std::fprintf(stderr, "\n");
        pairs_sum.add(t.pairs);
        if (t.passes_settled) {
            ++settled_steps;
            if (t.start_n >= 0) { set_start_n.add(t.start_n); set_start_t.add(t.start_t); }
            if (t.pred_n >= 0) { set_pred_n.add(t.pred_n); set_pred_t.add(t.pred_t); }
            continue;
        }
        if (t.iterations.empty() && t.newton_end == 0) continue;
        ++newton_steps;
        ++ends[t.newton_end];
        newton_its.add(static_cast<double>(t.iterations.size()));
        pass_solves.add(t.pass_solves);
        confirm.add(t.confirm_solves);
        solves.add(t.solves);
        if (t.smoothing_iterations > 0) {
            ++smoothing_steps;
            smoothing_ok += t.smoothing_ok;
            smooth.add(t.smoothing_iterations);
        }
        if (t.start_n >= 0) { start_n.add(t.start_n); start_t.add(t.start_t); }
        if (t.pred_n >= 0) { pred_n.add(t.pred_n); pred_t.add(t.pred_t); }
        if (t.first_n >= 0) { first_n.add(t.first_n); first_t.add(t.first_t); }
        if (t.passes_n >= 0) { passes_n.add(t.passes_n); passes_t.add(t.passes_t); }
        changed.add(t.pairs_changed);
        maxch.add(t.max_changes_per_pair);
        int ret = 0;
        for (std::size_t k = 0; k < t.iterations.size(); ++k) {
            const auto& it = t.iterations[k];
            ret += it.returns;
            const std::size_t b = std::min<std::size_t>(k, it_changes.size() - 1);
            it_changes[b].add(it.n_changes + it.t_changes);
            it_returns[b].add(it.returns);
            it_full[b].add(it.step == 1.0 ? 1.0 : 0.0);
            it_viol[b].add(it.violations);
        }
        returns.add(ret);
        revisit_steps += ret > 0;
    }
    std::fprintf(stderr, "# pairs %.0f; steps with a solve: passes settled %d (start->final n %.1f t %.1f, predicted->final n %.1f t %.1f)\n",
                 pairs_sum.mean(), settled_steps, set_start_n.mean(), set_start_t.mean(), set_pred_n.mean(), set_pred_t.mean());
    std::fprintf(stderr, "# Newton steps %d: solves %.2f = passes %.2f + Newton iterations %.2f + confirming passes %.2f (+ smoothing)\n",
                 newton_steps, solves.mean(), pass_solves.mean(), newton_its.mean(), confirm.mean());
    std::fprintf(stderr, "#   semismooth ends:");
    for (const auto& e : ends) std::fprintf(stderr, " [%d]=%d", e.first, e.second);
    std::fprintf(stderr, " (1 converged, 2 iteration limit, 3 no decrease, 4 singular, 5 handed to the homotopy from rest); smoothing in %d steps (%d settled), %.1f iterations each\n",
                 smoothing_steps, smoothing_ok, smooth.mean());
    std::fprintf(stderr, "#   distance to the final modes (pairs, normal / tangential): start %.1f / %.1f, predicted %.1f / %.1f, Newton's first %.1f / %.1f, after the passes %.1f / %.1f\n",
                 start_n.mean(), start_t.mean(), pred_n.mean(), pred_t.mean(), first_n.mean(), first_t.mean(), passes_n.mean(), passes_t.mean());
    std::fprintf(stderr, "#   pairs that changed in the Newton iterations %.1f, most changes of one pair %.1f, returns to a left mode %.1f per step (%d of %d steps)\n",
                 changed.mean(), maxch.mean(), returns.mean(), revisit_steps, newton_steps);
    std::fprintf(stderr, "#   per iteration (1..): changes / returns / full steps / violations after:");
    for (std::size_t k = 0; k < it_changes.size(); ++k)
        if (it_changes[k].n > 0)
            std::fprintf(stderr, " %zu:%.1f/%.1f/%.2f/%.0f(n%.0f)", k + 1, it_changes[k].mean(), it_returns[k].mean(),
                         it_full[k].mean(), it_viol[k].mean(), it_changes[k].n);
    std::fprintf(stderr, "\n");
    // where the mode-set solves go (docs/decisions/038): per phase and route, the calls, their
    // mean held rows and CPU time, over the first two steps (from rest) and the rest
    auto routes_table = [&](const char* label, std::size_t from, std::size_t to) {
        detail::sparse::RouteStats sum[detail::sparse::phase_count];
        double phase_s[detail::sparse::phase_count] = {};
        long transition = 0, recallable = 0, seen_earlier = 0;
        for (std::size_t i = from; i < std::min(to, steps.size()); ++i) {
            recallable += steps[i].recallable;
            seen_earlier += steps[i].seen_earlier;
            if (steps[i].solves == 0) continue;
            ++transition;
            for (int ph = 0; ph < detail::sparse::phase_count; ++ph) {
                sum[ph].add(steps[i].phase[ph]);
                phase_s[ph] += steps[i].phase_s[ph];
            }
        }
        std::fprintf(stderr, "# routes, %s (%ld transition steps; sets solved again in the same step %ld, solved in an earlier step %ld): per phase calls / mean held rows / CPU s per route; new-set solves per transition step; the phase's CPU s\n",
                     label, transition, recallable, seen_earlier);
        detail::sparse::RouteStats all;
        double all_s = 0.0;
        for (int ph = 0; ph < detail::sparse::phase_count; ++ph) {
            all.add(sum[ph]);
            all_s += phase_s[ph];
        }
        for (int ph = 0; ph <= detail::sparse::phase_count; ++ph) {
            const auto& rs = ph < detail::sparse::phase_count ? sum[ph] : all;
            std::fprintf(stderr, "#   %-10s", ph < detail::sparse::phase_count ? detail::sparse::phase_name(ph) : "all");
            for (int r = 0; r < detail::sparse::route_count; ++r)
                if (rs.count[r] > 0)
                    std::fprintf(stderr, " %s %ld/%.0f/%.2fs", detail::sparse::route_name(r), rs.count[r],
                                 rs.held[r] / static_cast<double>(rs.count[r]), rs.seconds[r]);
            std::fprintf(stderr, " | %.2f per step | %.2f s (KLU pivoted %ld)\n",
                         transition > 0 ? static_cast<double>(rs.solves()) / static_cast<double>(transition) : 0.0,
                         ph < detail::sparse::phase_count ? phase_s[ph] : all_s, rs.fixed_pivoted);
        }
    };
    routes_table("step 1", 0, 1);
    routes_table("steps 1-2", 0, 2);
    routes_table("steps 3-", 2, steps.size());
    routes_table("all steps", 0, steps.size());
}
BENCHMARK(TransitionStudy)
    ->ArgNames({"el", "stack", "ms", "way", "trace", "schur", "fixed", "path", "hits", "repair"})
    // decision 037: the changes one by one on the graduated 10 x 400, 30 / 100 ms, with the trace
    ->ArgsProduct({{400}, {1}, {30, 100}, {0, 1, 3, 7, 15, 23, 29, 31}, {1}, {0}, {-1}, {0}, {-1}, {-1}})
    // before / after: graduated 50 / 100 / 200 / 400 and identical 400, 30 / 100 ms; the same
    // meshes bonded (the targets' reference)
    ->ArgsProduct({{50, 100, 200, 400}, {1}, {100}, {0, 29, 31}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    ->ArgsProduct({{400}, {2}, {30, 100}, {0, 29, 31}, {0, 1}, {0}, {-1}, {0}, {-1}, {-1}})
    ->Args({400, 3, 100, 29, 0, 0, -1, 0, -1, -1})->Args({400, 4, 100, 29, 0, 0, -1, 0, -1, -1})
    // decision 038: the identical (and graduated) 10 x 400 stack's routes: the held sets' own KLU
    // systems (fixed 2 the fixed pattern, 3, 4 the default), the Schur way's limit
    ->ArgsProduct({{400}, {1, 2}, {30, 100}, {0, 32, 61}, {0, 1}, {0, 1, 200, 1000}, {2, 3, 4}, {0}, {-1}, {-1}})
    // decisions 037 and 038 together: before both (0), 037 alone (29), 038 alone (32), both (61)
    ->ArgsProduct({{50, 100, 200, 400}, {1}, {100}, {0, 29, 32, 61}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    ->ArgsProduct({{400}, {2}, {100}, {0, 29, 32, 61}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    ->ArgsProduct({{100, 200, 400}, {3, 4}, {100}, {61}, {0}, {0}, {-1}, {0}, {-1}, {-1}})
    // decision 040: the homotopy (path) on, a new base past 24 / 48 (its default) / 96 changed
    // rows or none (-1), against off (path 0: registered above without the trace), graduated
    // and identical 10 x 400 and graduated 100 / 200, 100 ms, every default else (way 61)
    ->ArgsProduct({{400}, {1, 2}, {100}, {61}, {1}, {0}, {-1}, {0, 24, 48, 96, -1}, {-1}, {-1}})
    ->ArgsProduct({{400}, {1, 2}, {100}, {61}, {0}, {0}, {-1}, {24, 48, 96, -1}, {-1}, {-1}})
    // the limit on the start modes' failing conditions: none (0), 300, 500 (the default, -1)
    ->ArgsProduct({{400}, {1, 2}, {100}, {61}, {0, 1}, {0}, {-1}, {48}, {0, 300}, {-1}})
    ->ArgsProduct({{100, 200}, {1}, {100}, {61}, {1}, {0}, {-1}, {0, 48}, {-1}, {-1}})
    ->ArgsProduct({{100, 200}, {1}, {100}, {61}, {0}, {0}, {-1}, {48}, {-1}, {-1}})
    // decision 041: the homotopy from rest off (way 125) against on (61, registered above for
    // graduated 100 / 200 / 400 and identical 400), with and without the trace; identical 100 / 200
    ->ArgsProduct({{100, 200, 400}, {1}, {100}, {125}, {0, 1}, {0}, {-1}, {48}, {-1}, {-1}})
    ->ArgsProduct({{400}, {2}, {100}, {125}, {0, 1}, {0}, {-1}, {48}, {-1}, {-1}})
    ->ArgsProduct({{100, 200}, {2}, {100}, {61, 125}, {0, 1}, {0}, {-1}, {48}, {-1}, {-1}})
    // decision 042: the homotopy's repairs off (0, the way before), the clamp's slip entry alone
    // (1), both (-1, the defaults), graduated and identical 100 / 200 / 400, 100 ms
    ->ArgsProduct({{100, 200, 400}, {1, 2}, {100}, {61}, {0, 1}, {0}, {-1}, {48}, {-1}, {0, 1}})
    // issue 27's per-doubling target from 50 elements per half leaf: graduated 10 x 50 with every
    // default and bonded (benchmarks/transition_targets.sh)
    ->Args({50, 1, 100, 61, 0, 0, -1, 48, -1, -1})->Args({50, 3, 100, 61, 0, 0, -1, 0, -1, -1})
    // decision 045: the homotopy's base kept across steps off (repair 7, the way before) against
    // on (-1, the defaults), graduated and identical 100 / 200 / 400, 100 ms
    ->ArgsProduct({{100, 200, 400}, {1, 2}, {100}, {61}, {0, 1}, {0}, {-1}, {48}, {-1}, {7}})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

/// Decision 050: the automatic path's choice (resolve_contact_path) against both paths forced,
/// every other default. args: elements per half leaf, stack (0 the paper example, friction; 5 the
/// paper example bonded; 6 the paper example, friction, elastic interfaces; 1 / 2 graduated /
/// identical 10 leaves, friction, elastic interfaces, as TransitionStudy; 3 / 4 the same bonded),
/// simulated ms, path (0 automatic, 1 dense, 2 sparse). Counters as ElasticRuns (cpu_s_per_sim_s:
/// CPU s per simulated second, set-up and stepping); the answer at the end to stderr (17 digits).
void PathChoice(benchmark::State& state) {
    const int elements = static_cast<int>(state.range(0));
    const int stack = static_cast<int>(state.range(1));
    ModelSpec spec = stack == 0 || stack == 6 ? paper_example(PaperCase::friction, PaperExampleOptions{elements})
                     : stack == 5             ? paper_example(PaperCase::bonded, PaperExampleOptions{elements})
                     : stack == 1 || stack == 3 ? graduated_stack(elements, 10)
                                                : paper_stack(PaperCase::friction, elements, 10);
    for (auto& f : spec.interfaces) {
        if (stack == 1 || stack == 2 || stack == 6) f.contact = InterfaceContact::elastic;
        if (stack == 3 || stack == 4) f.law = InterfaceLaw::bonded;
    }
    SimulationOptions so;
    so.t_end_s = 1e-3 * static_cast<double>(state.range(2));
    so.stop_on_nonconvergence = false;
    const int path = static_cast<int>(state.range(3));
    so.contact_path = path == 1 ? ContactPath::dense : path == 2 ? ContactPath::sparse : ContactPath::automatic;
    ElasticFigures fig;
    for (auto _ : state) fig.run(spec, so);
    fig.put(state, so.t_end_s);
    const int rows = fig.components;
    state.counters["auto_sparse"] =
        resolve_contact_path(ContactPath::automatic, rows, so.solver.kind) == ContactPath::sparse ? 1.0 : 0.0;
    std::fprintf(stderr, "# PathChoice el:%d stack:%d path:%d rows %d answer: w %.17g m, dissipated %.17g J, |z| %.17g\n",
                 elements, stack, path, rows, fig.final_w_m, fig.dissipated_j, fig.z_norm);
}
BENCHMARK(PathChoice)
    ->ArgNames({"el", "stack", "ms", "path"})
    // the graduated 10-leaf spring (about 10.8 rows per element per half leaf) and the paper
    // example's 3 leaves on finer meshes (about 3.9), 100 ms; the crossover's neighbourhood
    ->ArgsProduct({{8, 12, 14, 16, 18, 25, 50, 100}, {1, 3}, {100}, {0, 1, 2}})
    ->ArgsProduct({{20, 30, 40, 50, 80, 160}, {0, 5, 6}, {100}, {0, 1, 2}})
    // whole seconds: the paper example (friction, bonded) and the graduated 10 x 12 / 14 friction
    ->ArgsProduct({{20}, {0, 5}, {1000}, {0, 1, 2}})->ArgsProduct({{12, 14}, {1}, {1000}, {0, 1, 2}})
    // identical 10 leaves, friction and bonded
    ->ArgsProduct({{8, 12, 25, 50}, {2, 4}, {100}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)->Iterations(1);

