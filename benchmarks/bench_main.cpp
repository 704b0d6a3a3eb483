// bench_stackbeam: the benchmarks of stackbeam (Google Benchmark; built with
// -DSTACKBEAM_BUILD_BENCHMARKS=ON, not run as tests). Figures and the commands that made them:
// docs/performance.md. The benchmarks by concern:
//  - bench_paper.cpp: ContactSolve, WholeRun, Inertia, MassiveStack, StressOutput (the paper
//    example's solvers and runs, leaf mass, the stress output);
//  - bench_scaling.cpp: Scaling, Transitions, FrictionMeshRatioRuns, ElasticRuns (many-leaf stacks);
//  - bench_transition_study.cpp: TransitionStudy, PathChoice (the sparse path's decision studies);
//  - bench_windup.cpp: WindupRig (the windup rig's loop against the vertical rig's).
// They register in that order (the files' order in benchmarks/CMakeLists.txt), the order of the
// one file they came from.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
