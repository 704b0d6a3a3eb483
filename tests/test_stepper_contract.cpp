// The contract every Stepper keeps (stepper.hpp), checked on every stepper make_stepper builds
// (closed-form dense and sparse, newmark, cvode massless, held, modal and massive) on short
// runs of the paper example: records on the dt grid and the record index with them,
// the energy balance within the mode's bound, one PairRecord per pair at every record
// (simulate's per-pair observer included), and counters that agree with the records.
#define BOOST_TEST_MODULE stepper_contract
#include <boost/test/unit_test.hpp>
#include <algorithm>
#include <cmath>
#include <string>

#include "stackbeam/model/paper_example.hpp"
#include "stackbeam/time/stepper.hpp"
#include "test_support.hpp"

using namespace stackbeam;

namespace {

struct Config {
    PaperCase paper_case = PaperCase::friction;
    double density_kg_per_m3 = 0.0;  ///< of every leaf
    SimulationOptions options;
    /// Bound on |energy_balance_error_j| relative to the initial energy E0, the mode's own:
    /// stated per configuration below.
    double energy_bound = 0.0;
    bool fixed_step = true;          ///< one step per record (closed-form, newmark)
    /// The whole massive stack (CvodeMassiveStepper): every interface elastic, the clamps 10 mm
    /// long (an elastic layer over them), 10 elements per half leaf.
    bool massive_stack = false;
};

SimulationOptions base_options(Mode mode, double dt_s, double t_end_s) {
    SimulationOptions o;
    o.mode = mode;
    o.dt_s = dt_s;
    o.t_end_s = t_end_s;
    return o;
}

// closed-form: eq. 16 is exact for contact forces linear over a step (eq. 14); the
// balance error is the discretisation of that assumption and of the trapezoidal friction
// work, O(dt^2) per unit time: measured 3.7e-7 E0 (dense and sparse alike, friction case,
// dt 1 ms, 50 ms); bound 1e-5 E0 (the paper's 0.6 s runs reach 4e-4 E0 at this dt).
Config closed_form(ContactPath path) {
    Config c;
    c.options = base_options(Mode::closed_form, 1e-3, 0.05);
    c.options.contact_path = path;
    c.energy_bound = 1e-5;
    return c;
}

// newmark: the step's energy identity holds exactly (newmark_stepper.hpp), so the balance
// closes to round-off of E0 over the steps (200 here): 1e-9 E0 (measured 5e-12 with steel
// leaves, 8e-12 massless).
Config newmark(double density) {
    Config c;
    c.density_kg_per_m3 = density;
    c.options = base_options(Mode::newmark, 1e-4, 0.02);
    c.energy_bound = 1e-9;
    return c;
}

// cvode: each CVODE step commits a local error ~ rtol of the state, so the balance drifts
// by up to ~ N rtol E0 over N steps (tens to hundreds here, rtol 1e-8): bound 1e-5 E0
// (measured 9e-8 E0 massless, 3e-8 and 2e-8 with leaf mass).
Config cvode(PaperCase pc, double density) {
    Config c;
    c.paper_case = pc;
    c.density_kg_per_m3 = density;
    c.options = base_options(Mode::cvode, 1e-3, pc == PaperCase::friction && density == 0.0 ? 0.05 : 0.02);
    c.energy_bound = 1e-5;
    c.fixed_step = false;
    return c;
}

// the whole massive stack under cvode: BDF with Newton, events on every transition; the
// dissipated energy is a state of the ODE, so the balance follows CVODE's local error control
// as above: bound 1e-5 E0 at rtol 1e-8 (test_cvode_massive bounds it by 1e3 rtol E0; measured
// 3e-11 E0 over 2 ms). 1 ms at 0.1 ms outputs (the layer's ~50 kHz vibration makes its steps
// short: 10 records suffice).
Config cvode_massive() {
    Config c;
    c.density_kg_per_m3 = 7850.0;
    c.options = base_options(Mode::cvode, 1e-4, 1e-3);
    c.options.cvode.leaf_inertia = LeafInertia::massive;
    c.options.solver.tolerance_m = 1e-9;
    c.energy_bound = 1e-5;
    c.fixed_step = false;
    c.massive_stack = true;
    return c;
}

void check_contract(const Config& cfg) {
    const ModelSpec spec = testing::paper_with_mass(cfg.paper_case, cfg.density_kg_per_m3, cfg.massive_stack);
    const System system(Model::build(spec));
    const SimulationOptions& o = cfg.options;
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
    if (cfg.massive_stack) {  // the massive stepper ran: no retained modes, Newton's Jacobians
        BOOST_TEST(report.cvode.retained_modes == 0);
        BOOST_TEST(report.cvode.jacobian_evaluations > 0);
    }

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

BOOST_AUTO_TEST_CASE(closed_form_dense) { check_contract(closed_form(ContactPath::dense)); }
BOOST_AUTO_TEST_CASE(closed_form_sparse) { check_contract(closed_form(ContactPath::sparse)); }
BOOST_AUTO_TEST_CASE(cvode_massless) { check_contract(cvode(PaperCase::friction, 0.0)); }
BOOST_AUTO_TEST_CASE(newmark_massless) { check_contract(newmark(0.0)); }
BOOST_AUTO_TEST_CASE(newmark_steel) { check_contract(newmark(7850.0)); }
// leaf mass on a bonded stack: held-for-good contact (CvodeHeldStepper)
BOOST_AUTO_TEST_CASE(cvode_leaf_mass_bonded) { check_contract(cvode(PaperCase::bonded, 7850.0)); }
// leaf mass with friction: modal inertia with events (CvodeModalStepper)
BOOST_AUTO_TEST_CASE(cvode_leaf_mass_friction) { check_contract(cvode(PaperCase::friction, 7850.0)); }
// leaf mass with friction on elastic interfaces: the whole massive stack (CvodeMassiveStepper)
BOOST_AUTO_TEST_CASE(cvode_leaf_mass_massive_stack) { check_contract(cvode_massive()); }
