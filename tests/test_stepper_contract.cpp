// The contract every Stepper keeps (stepper.hpp), checked on every stepper make_stepper can build:
// one case per row of the registry (lib/time/stepper_registry.hpp), its scenario derived from the
// row (leaf mass, friction or a bonded stack, rigid contact or an elastic layer on every row) and
// checked to reach that row, on both contact paths where the mode has them; a stepper is covered
// by being registered. On short runs of the paper example: records on the dt grid and the record
// index with them, the energy balance within the mode's bound, one PairRecord per pair at every
// record (simulate's per-pair observer included), and counters that agree with the records.
#define BOOST_TEST_MODULE stepper_contract
#include <boost/test/data/test_case.hpp>
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/stepper.hpp"
#include "time/stepper_registry.hpp"

using namespace stackbeam;
namespace bdata = boost::unit_test::data;

namespace {

struct Config {
    PaperCase paper_case = PaperCase::friction;
    double density_kg_per_m3 = 0.0;  ///< of every leaf
    SimulationOptions options;
    /// Bound on |energy_balance_error_j| relative to the initial energy E0, the mode's own:
    /// stated per mode below.
    double energy_bound = 0.0;
    bool fixed_step = true;          ///< one step per record (closed-form, newmark)
    /// Every interface elastic, the clamps 10 mm long (an elastic layer over them), 10 elements
    /// per half leaf: the scenario of a stepper that takes no rigid contact row.
    bool elastic_stack = false;
};

SimulationOptions base_options(Mode mode, double dt_s, double t_end_s) {
    SimulationOptions o;
    o.mode = mode;
    o.dt_s = dt_s;
    o.t_end_s = t_end_s;
    return o;
}

/// The scenario and options of registry row `row` on contact path `path`, and the mode's bound.
Config config_of(const detail::StepperCapabilities& row, ContactPath path) {
    Config c;
    c.paper_case = row.friction ? PaperCase::friction : PaperCase::bonded;
    c.density_kg_per_m3 = row.massive_leaves ? 7850.0 : 0.0;
    c.elastic_stack = !row.rigid_rows;
    switch (row.mode) {
        case Mode::closed_form:
            // eq. 16 is exact for contact forces linear over a step (eq. 14); the balance error is
            // the discretisation of that assumption and of the trapezoidal friction work, O(dt^2)
            // per unit time: measured 3.7e-7 E0 (dense and sparse alike, friction case, dt 1 ms,
            // 50 ms); bound 1e-5 E0 (the paper's 0.6 s runs reach 4e-4 E0 at this dt).
            c.options = base_options(Mode::closed_form, 1e-3, 0.05);
            c.energy_bound = 1e-5;
            break;
        case Mode::newmark:
            // the step's energy identity holds exactly (newmark_stepper.hpp), so the balance closes
            // to round-off of E0 over the steps (200 here): 1e-9 E0 (measured 5e-12 with steel
            // leaves, 8e-12 massless).
            c.options = base_options(Mode::newmark, 1e-4, 0.02);
            c.energy_bound = 1e-9;
            break;
        case Mode::cvode:
            // each CVODE step commits a local error ~ rtol of the state, so the balance drifts by
            // up to ~ N rtol E0 over N steps (tens to hundreds here, rtol 1e-8): bound 1e-5 E0
            // (measured 9e-8 E0 massless, 3e-8 and 2e-8 with leaf mass; the whole massive stack
            // 3e-11 E0 over 2 ms, its dissipated energy a state of the ODE). The elastic stack:
            // 1 ms at 0.1 ms outputs (the layer's ~50 kHz vibration makes its steps short: 10
            // records suffice), the contact tolerance 1e-9 m.
            c.options = c.elastic_stack ? base_options(Mode::cvode, 1e-4, 1e-3)
                                        : base_options(Mode::cvode, 1e-3, row.friction && !row.massive_leaves ? 0.05 : 0.02);
            if (c.elastic_stack) c.options.solver.tolerance_m = 1e-9;
            c.options.cvode.leaf_inertia = c.elastic_stack ? LeafInertia::massive : LeafInertia::automatic;
            c.energy_bound = 1e-5;
            c.fixed_step = false;
            break;
    }
    c.options.contact_path = path;
    return c;
}

/// Every (row, contact path) of the registry: both paths where the mode has a sparse one.
struct Case {
    std::string row;
    ContactPath path;
};
std::ostream& operator<<(std::ostream& os, const Case& c) {
    return os << c.row << (c.path == ContactPath::sparse ? " (sparse path)" : "");
}
std::vector<Case> registered_cases() {
    std::vector<Case> cases;
    for (const detail::StepperCapabilities& row : detail::stepper_registry()) {
        cases.push_back({row.name, ContactPath::dense});
        if (row.mode != Mode::cvode) cases.push_back({row.name, ContactPath::sparse});
    }
    return cases;
}

void check_contract(const detail::StepperCapabilities& row, const Config& cfg) {
    PaperExampleOptions po;
    if (cfg.elastic_stack) po.elements_per_half_leaf = 10;
    ModelSpec spec = paper_example(cfg.paper_case, po);
    for (auto& leaf : spec.leaves) leaf.density_kg_per_m3 = cfg.density_kg_per_m3;
    if (cfg.elastic_stack) {
        for (auto& f : spec.interfaces) f.contact = InterfaceContact::elastic;
        for (auto& cl : spec.clamps) cl.length_m = 0.01;
    }
    const System system(Model::build(spec));
    const SimulationOptions& o = cfg.options;
    // the scenario derived from the row reaches it (else the row is not covered: make its
    // scenario in config_of)
    BOOST_TEST_REQUIRE(std::string(detail::choose_stepper(system, o).name) == row.name);
    const long n = static_cast<long>(std::ceil(o.t_end_s / o.dt_s - 1e-9));
    const std::size_t np = system.pairs().size();

    // simulate(): records, the per-pair observer and the report
    std::vector<double> observed_t;
    bool every_pair = true;
    RunReport report;
    const std::vector<StepRecord> records = simulate(
        system, o, {}, &report, [&](double t_s, const std::vector<PairRecord>& pairs) {
            observed_t.push_back(t_s);
            bool ok = pairs.size() == np;
            for (std::size_t k = 0; ok && k < np; ++k) ok = pairs[k].pair == static_cast<int>(k);
            every_pair = every_pair && ok;
        });
    BOOST_TEST_REQUIRE(records.size() == static_cast<std::size_t>(n + 1));

    // the per-pair observer: once per record, at its time, with every pair in order
    BOOST_TEST_REQUIRE(observed_t.size() == records.size());
    for (std::size_t i = 0; i < records.size(); ++i) BOOST_TEST(observed_t[i] == records[i].t_s);
    BOOST_TEST(every_pair);

    // the dt grid: t_i = i dt to round-off (a few ulp of t_end)
    const double e0 = records[0].kinetic_energy_j + records[0].strain_energy_j;
    BOOST_TEST_REQUIRE(e0 > 0.0);
    double worst_energy = 0.0;
    long iterations = 0, factorizations = 0;
    for (std::size_t i = 0; i < records.size(); ++i) {
        BOOST_TEST(std::abs(records[i].t_s - static_cast<double>(i) * o.dt_s) <= 1e-14 * o.t_end_s);
        worst_energy = std::max(worst_energy, std::abs(records[i].energy_balance_error_j));
        BOOST_TEST(records[i].contact_iterations >= 0);
        BOOST_TEST(records[i].factorizations >= 0);
        iterations += records[i].contact_iterations;
        factorizations += records[i].factorizations;
    }
    BOOST_TEST_MESSAGE("max |energy balance error| / E0 = " << worst_energy / e0);
    BOOST_TEST(worst_energy <= cfg.energy_bound * e0);

    // counters
    BOOST_TEST(std::string(to_string(report.mode)) == to_string(o.mode));
    BOOST_TEST(report.contact_iterations >= 0);
    BOOST_TEST(report.factorizations >= 0);
    if (cfg.fixed_step) {
        // one step per record after the first; the report is the sum over the records
        BOOST_TEST(report.steps == n);
        BOOST_TEST(report.contact_iterations == iterations);
        BOOST_TEST(report.factorizations == factorizations);
    } else {
        // CVODE's steps are its own (fewer than records when the motion is smooth); the
        // records carry the iterations up to their time, the report every one
        BOOST_TEST(report.steps == report.cvode.steps);
        BOOST_TEST(report.steps > 0);
        BOOST_TEST(report.contact_iterations >= iterations);
        BOOST_TEST(report.cvode.restarts >= 0);
        BOOST_TEST(std::is_sorted(report.events.begin(), report.events.end(),
                                  [](const ContactEvent& a, const ContactEvent& b) { return a.t_s < b.t_s; }));
    }
    // the outputs the row gives: the leaves' kinetic energy (they move with R), CVODE's counters
    double leaf_kinetic = 0.0;
    for (const StepRecord& r : records) leaf_kinetic = std::max(leaf_kinetic, r.leaf_kinetic_energy_j);
    BOOST_TEST((leaf_kinetic > 0.0) == row.leaf_kinetic_energy);
    BOOST_TEST((report.cvode.steps > 0) == row.cvode_stats);

    // the stepper itself: the record index follows advance(), pairs() at every record,
    // and it reproduces simulate()'s records (simulate is a loop over it)
    const std::unique_ptr<Stepper> stepper = make_stepper(system, o);
    BOOST_TEST(stepper->record_index() == 0);
    BOOST_TEST(stepper->pairs().size() == np);
    const long k = std::min<long>(n, 5);
    for (long i = 1; i <= k; ++i) {
        const StepRecord& r = stepper->advance();
        BOOST_TEST(stepper->record_index() == i);
        BOOST_TEST(&r == &stepper->current());
        BOOST_TEST(r.w_m == records[static_cast<std::size_t>(i)].w_m);
        BOOST_TEST(stepper->pairs().size() == np);
    }
}

}  // namespace

BOOST_DATA_TEST_CASE(every_registered_stepper, bdata::make(registered_cases()), c) {
    const detail::StepperCapabilities& row = detail::registered_stepper(c.row);
    check_contract(row, config_of(row, c.path));
}
