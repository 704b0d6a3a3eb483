# CTest registrations of the command line `stackbeam` (target stackbeam_cli).
#
# Included from tests/CMakeLists.txt:
#   if(TARGET stackbeam_cli)
#     include(${CMAKE_CURRENT_SOURCE_DIR}/cli_tests.cmake)
#   endif()
#
# This file is also the checker the tests run (`cmake -P cli_tests.cmake`, script
# mode below): it runs the CLI and checks its exit status, that a message names
# the option, and the output file. PASS_REGULAR_EXPRESSION alone would not do:
# it ignores the exit status.

if(CMAKE_SCRIPT_MODE_FILE)
  # ---- script mode: one check ----------------------------------------------------------
  # -DCLI=<exe> -DARGS=<args separated by |> -DEXPECT_RC=<n> [-DEXPECT_TEXT=<substring of stdout+stderr>]
  # [-DOUT=<file that must exist after the run, or must not when EXPECT_RC != 0>]
  # [-DHEADER_PREFIX=<prefix of OUT's first line>] [-DMIN_LINES=<n>]
  # [-DJSON=<a JSON file the run writes> -DJSON_PATH=<keys separated by |> -DJSON_RANGE=<lo|hi>]:
  #   the number at JSON_PATH in JSON must lie in [lo, hi]; [-DJSON_TEXT=<text>] instead: the string
  #   at JSON_PATH must contain it; [-DJSON_ABSENT=<key>]: JSON has no top-level key of that name
  # [-DNOT_TEXT=<text stdout+stderr must not contain>]
  string(REPLACE "|" ";" args "${ARGS}")
  if(DEFINED OUT)
    file(REMOVE "${OUT}" "${OUT}.partial")
  endif()
  execute_process(COMMAND "${CLI}" ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  list(JOIN args " " args_text)
  message(STATUS "stackbeam ${args_text}\n-- exit status ${rc}\n-- stdout:\n${out}\n-- stderr:\n${err}")
  if(NOT rc STREQUAL "${EXPECT_RC}")
    message(FATAL_ERROR "exit status ${rc}, expected ${EXPECT_RC}")
  endif()
  if(DEFINED EXPECT_TEXT)
    string(FIND "${out}${err}" "${EXPECT_TEXT}" pos)
    if(pos EQUAL -1)
      message(FATAL_ERROR "the output does not contain '${EXPECT_TEXT}'")
    endif()
  endif()
  if(DEFINED NOT_TEXT)
    string(FIND "${out}${err}" "${NOT_TEXT}" pos)
    if(NOT pos EQUAL -1)
      message(FATAL_ERROR "the output contains '${NOT_TEXT}'")
    endif()
  endif()
  if(DEFINED OUT)
    if(EXPECT_RC EQUAL 0)
      if(NOT EXISTS "${OUT}")
        message(FATAL_ERROR "${OUT} was not written")
      endif()
      if(EXISTS "${OUT}.partial")
        message(FATAL_ERROR "${OUT}.partial was left behind by a successful run")
      endif()
      file(STRINGS "${OUT}" lines)
      list(LENGTH lines n)
      list(GET lines 0 header)
      if(DEFINED HEADER_PREFIX)
        string(FIND "${header}" "${HEADER_PREFIX}" pos)
        if(NOT pos EQUAL 0)
          message(FATAL_ERROR "header '${header}' does not start with '${HEADER_PREFIX}'")
        endif()
      endif()
      if(DEFINED MIN_LINES AND n LESS MIN_LINES)
        message(FATAL_ERROR "${OUT} has ${n} lines, expected at least ${MIN_LINES}")
      endif()
    elseif(EXISTS "${OUT}")
      message(FATAL_ERROR "${OUT} exists after a failed run")
    endif()
  endif()
  if(DEFINED JSON)
    file(READ "${JSON}" json_text)
  endif()
  if(DEFINED JSON AND DEFINED JSON_ABSENT)
    string(JSON value ERROR_VARIABLE json_error GET "${json_text}" "${JSON_ABSENT}")
    if(NOT json_error)
      message(FATAL_ERROR "${JSON} has the key '${JSON_ABSENT}': ${value}")
    endif()
    message(STATUS "${JSON}: no key '${JSON_ABSENT}'")
  elseif(DEFINED JSON)
    string(REPLACE "|" ";" json_keys "${JSON_PATH}")
    string(JSON value ERROR_VARIABLE json_error GET "${json_text}" ${json_keys})
    if(json_error)
      message(FATAL_ERROR "${JSON}: ${JSON_PATH}: ${json_error}")
    endif()
  endif()
  if(DEFINED JSON AND DEFINED JSON_TEXT)
    string(FIND "${value}" "${JSON_TEXT}" pos)
    if(pos EQUAL -1)
      message(FATAL_ERROR "${JSON}: ${JSON_PATH} = '${value}' does not contain '${JSON_TEXT}'")
    endif()
    message(STATUS "${JSON_PATH} contains '${JSON_TEXT}'")
  elseif(DEFINED JSON AND DEFINED JSON_RANGE)
    string(REPLACE "|" ";" range "${JSON_RANGE}")
    list(GET range 0 lo)
    list(GET range 1 hi)
    # if(LESS/GREATER) compare the values as floating-point numbers
    if(value LESS lo OR value GREATER hi)
      message(FATAL_ERROR "${JSON}: ${JSON_PATH} = ${value}, expected in [${lo}, ${hi}]")
    endif()
    message(STATUS "${JSON_PATH} = ${value} in [${lo}, ${hi}]")
  endif()
  return()
endif()

# ---- configure mode: the registrations -------------------------------------------------

# stackbeam_cli_test(NAME <name> ARGS <arg>... EXPECT_RC <n> [EXPECT_TEXT <text>] [OUT <file>]
#                    [NOT_TEXT <text>] [HEADER_PREFIX <prefix>] [MIN_LINES <n>]
#                    [JSON <file> JSON_PATH <keys> (JSON_RANGE <lo|hi> | JSON_TEXT <text>) | JSON_ABSENT <key>])
function(stackbeam_cli_test)
  cmake_parse_arguments(T "" "NAME;EXPECT_RC;EXPECT_TEXT;NOT_TEXT;OUT;HEADER_PREFIX;MIN_LINES;JSON;JSON_PATH;JSON_RANGE;JSON_TEXT;JSON_ABSENT" "ARGS" ${ARGN})
  string(REPLACE ";" "|" args "${T_ARGS}")
  set(defs -DCLI=$<TARGET_FILE:stackbeam_cli> "-DARGS=${args}" -DEXPECT_RC=${T_EXPECT_RC})
  foreach(opt EXPECT_TEXT NOT_TEXT OUT HEADER_PREFIX MIN_LINES JSON JSON_PATH JSON_RANGE JSON_TEXT JSON_ABSENT)
    if(DEFINED T_${opt})
      list(APPEND defs "-D${opt}=${T_${opt}}")
    endif()
  endforeach()
  add_test(NAME ${T_NAME} COMMAND ${CMAKE_COMMAND} ${defs} -P ${CMAKE_CURRENT_LIST_FILE})
  set_tests_properties(${T_NAME} PROPERTIES LABELS cli TIMEOUT 60)
  if(DEFINED T_OUT)  # tests of one output file run one at a time (a bad run checks it is not written)
    set_tests_properties(${T_NAME} PROPERTIES RESOURCE_LOCK ${T_OUT})
  endif()
endfunction()

set(_cli_out_dir ${CMAKE_CURRENT_BINARY_DIR})

# Bad arguments: exit status 2, a message naming the option, no output file.
# name            option value       text the message must contain
set(_cli_bad_cases
  "case_unknown|--case|foo|--case: value 'foo'"
  "elements_zero|--elements|0|--elements: value '0'"
  "elements_negative|--elements|-3|--elements: value '-3'"
  "dt_zero|--dt|0|--dt: value '0'"
  "dt_negative|--dt|-1e-3|--dt: value '-1e-3'"
  "dt_nan|--dt|nan|--dt: value 'nan' is not allowed: must be a finite number > 0 [s]"
  "dt_trailing|--dt|1e-3x|--dt: value '1e-3x'"
  "t_end_inf|--t-end|inf|--t-end: value 'inf'"
  "tol_zero|--tol|0|--tol: value '0'"
  "solver_unknown|--solver|magic|--solver: value 'magic'"
  "mode_unknown|--mode|rk4|--mode: value 'rk4'"
  "rtol_zero|--rtol|0|--rtol: value '0'"
  "rtol_nan|--rtol|nan|--rtol: value 'nan'"
  "rtol_too_large|--rtol|0.5|--rtol: value '0.5' is not allowed: must be a number in [1e-14, 0.01]"
  "rtol_one|--rtol|1|--rtol: value '1' is not allowed: must be a number in [1e-14, 0.01]"
  "atol_negative|--atol|-1e-9|--atol: value '-1e-9'"
  "max_step_negative|--max-step|-1|--max-step: value '-1' is not allowed: must be a finite number >= 0 [s] (0: no limit)"
  "tolerance_zero|--tolerance|0|--tolerance: value '0' is not allowed: must be a finite number > 0 [m]"
  "max_iterations_fraction|--max-iterations|2.5|--max-iterations: value '2.5' is not an integer"
  "tau_rule_unknown|--tau-rule|later|--tau-rule: value 'later' is not a tau rule"
  "events_without_cvode|--events|ev.csv|the event log exists in mode cvode only"
  "contact_path_unknown|--contact-path|banded|--contact-path: value 'banded' is not a contact path: allowed auto, dense, sparse"
  "beam_density_negative|--beam-density|-7850|--beam-density: value '-7850' is not allowed: must be a finite number >= 0 [kg/m^3]"
  "beam_density_nan|--beam-density|nan|--beam-density: value 'nan' is not allowed"
  "beam_density_massless_mode|--beam-density|7850|--beam-density: value '7850' needs --mode newmark"
  "interface_unknown|--interface|bogus|--interface: value 'bogus' is not allowed: must be 'rigid' or 'elastic'"
)
foreach(entry IN LISTS _cli_bad_cases)
  string(REPLACE "|" ";" fields "${entry}")
  list(GET fields 0 name)
  list(GET fields 1 option)
  list(GET fields 2 value)
  list(GET fields 3 text)
  set(out ${_cli_out_dir}/cli_bad_${name}.csv)
  # a short, otherwise good run with the one bad value
  set(args simulate --out ${out})
  if(NOT option STREQUAL "--case")
    list(APPEND args --case frictionless)
  endif()
  if(NOT option STREQUAL "--t-end")
    list(APPEND args --t-end 0.01)
  endif()
  if(option MATCHES "^--(rtol|atol|max-step)$")
    list(APPEND args --mode cvode)
  endif()
  list(APPEND args ${option} ${value})
  stackbeam_cli_test(NAME cli_bad_${name} ARGS ${args} EXPECT_RC 2 EXPECT_TEXT "${text}" OUT ${out})
endforeach()

stackbeam_cli_test(NAME cli_missing_out ARGS simulate --case frictionless --t-end 0.01
                   EXPECT_RC 2 EXPECT_TEXT "--out")
stackbeam_cli_test(NAME cli_missing_subcommand ARGS --case frictionless EXPECT_RC 2 EXPECT_TEXT "stackbeam: error:")
stackbeam_cli_test(NAME cli_help ARGS --help EXPECT_RC 0 EXPECT_TEXT "simulate")
stackbeam_cli_test(NAME cli_simulate_help ARGS simulate --help EXPECT_RC 0 EXPECT_TEXT "--alpha-fraction")

# The sparse contact path needs the exact solver: a clear error naming the option.
stackbeam_cli_test(NAME cli_bad_contact_path_solver
                   ARGS simulate --case friction --t-end 0.01 --contact-path sparse --solver accelerated
                        --out ${_cli_out_dir}/cli_bad_contact_path_solver.csv
                   EXPECT_RC 2 EXPECT_TEXT "--contact-path: value 'sparse' needs the exact solver"
                   OUT ${_cli_out_dir}/cli_bad_contact_path_solver.csv)
# A good run on the sparse path.
stackbeam_cli_test(NAME cli_ok_sparse
                   ARGS simulate --case friction --t-end 0.01 --contact-path sparse --out ${CMAKE_BINARY_DIR}/cli_sparse.csv
                   EXPECT_RC 0 EXPECT_TEXT "contact path               sparse" OUT ${CMAKE_BINARY_DIR}/cli_sparse.csv
                   HEADER_PREFIX "t,w,w_dot" MIN_LINES 12)

# A good run: exit status 0, a complete CSV (header + 11 records for 10 steps), no .partial.
stackbeam_cli_test(NAME cli_ok_frictionless
                   ARGS simulate --case frictionless --t-end 0.01 --out ${CMAKE_BINARY_DIR}/cli_ok.csv
                   EXPECT_RC 0 EXPECT_TEXT "steps" OUT ${CMAKE_BINARY_DIR}/cli_ok.csv
                   HEADER_PREFIX "t,w,w_dot,force_on_mass,probe_friction_force" MIN_LINES 12)

# Mode cvode: a complete CSV on the output grid and the event log (header + transitions).
stackbeam_cli_test(NAME cli_ok_cvode_friction
                   ARGS simulate --case friction --mode cvode --t-end 0.1 --rtol 1e-8
                        --events ${CMAKE_BINARY_DIR}/cli_cvode_events.csv --out ${CMAKE_BINARY_DIR}/cli_cvode.csv
                   EXPECT_RC 0 EXPECT_TEXT "event times" OUT ${CMAKE_BINARY_DIR}/cli_cvode.csv
                   HEADER_PREFIX "t,w,w_dot,force_on_mass,probe_friction_force" MIN_LINES 102)
stackbeam_cli_test(NAME cli_ok_cvode_events_file
                   ARGS simulate --case friction --mode cvode --t-end 0.1
                        --events ${CMAKE_BINARY_DIR}/cli_cvode_events2.csv --out ${CMAKE_BINARY_DIR}/cli_cvode2.csv
                   EXPECT_RC 0 OUT ${CMAKE_BINARY_DIR}/cli_cvode_events2.csv
                   HEADER_PREFIX "t,interface,x,pair,from,to,cause,w,w_dot" MIN_LINES 40)
# A CVODE failure (here: more steps needed than --max-steps allows with --max-step 1e-6 s)
# exits 3 with the time and leaves no output.
stackbeam_cli_test(NAME cli_cvode_failure
                   ARGS simulate --case friction --mode cvode --t-end 0.1 --max-step 1e-6 --max-steps 1000
                        --out ${CMAKE_BINARY_DIR}/cli_cvode_fail.csv
                   EXPECT_RC 3 EXPECT_TEXT "cvode mode" OUT ${CMAKE_BINARY_DIR}/cli_cvode_fail.csv)
# Mode newmark: leaves with mass (--beam-density), a complete CSV with the energy columns.
stackbeam_cli_test(NAME cli_ok_newmark
                   ARGS simulate --case bonded --mode newmark --beam-density 7850 --t-end 0.01
                        --out ${CMAKE_BINARY_DIR}/cli_newmark.csv
                   EXPECT_RC 0 EXPECT_TEXT "mode newmark" OUT ${CMAKE_BINARY_DIR}/cli_newmark.csv
                   HEADER_PREFIX "t,w,w_dot,force_on_mass,probe_friction_force" MIN_LINES 12)
stackbeam_cli_test(NAME cli_ok_newmark_scenario
                   ARGS simulate --scenario ${PROJECT_SOURCE_DIR}/scenarios/paper_friction.toml --mode newmark
                        --beam-density 7850 --t-end 0.01 --out ${_cli_out_dir}/cli_newmark_scenario.csv
                   EXPECT_RC 0 EXPECT_TEXT "mode newmark" OUT ${_cli_out_dir}/cli_newmark_scenario.csv MIN_LINES 12)
# Loadings with leaf mass (docs/model-and-scenarios.md "Loadings"): gravity (the leaves' weight
# too) in mode newmark from a massless example scenario, and the steel base-excitation example.
stackbeam_cli_test(NAME cli_ok_newmark_gravity
                   ARGS simulate --scenario ${PROJECT_SOURCE_DIR}/scenarios/gravity_friction.toml --mode newmark
                        --beam-density 7850 --dt 1e-4 --t-end 0.01 --out ${_cli_out_dir}/cli_newmark_gravity.csv
                   EXPECT_RC 0 EXPECT_TEXT "mode newmark" OUT ${_cli_out_dir}/cli_newmark_gravity.csv MIN_LINES 12)
stackbeam_cli_test(NAME cli_ok_newmark_base_excitation
                   ARGS simulate --scenario ${PROJECT_SOURCE_DIR}/scenarios/base_steel_elastic.toml --t-end 0.01
                        --out ${_cli_out_dir}/cli_newmark_base.csv
                   EXPECT_RC 0 EXPECT_TEXT "mode newmark" OUT ${_cli_out_dir}/cli_newmark_base.csv MIN_LINES 12)
# A file's event log with the mode changed on the command line: the file's key is named.
stackbeam_cli_test(NAME cli_bad_events_from_file_in_newmark
                   ARGS simulate --scenario ${PROJECT_SOURCE_DIR}/scenarios/base_friction.toml --mode newmark
                        --beam-density 7850 --t-end 0.01 --out ${_cli_out_dir}/cli_newmark_base_bad.csv
                   EXPECT_RC 2 EXPECT_TEXT "outputs.events_path" OUT ${_cli_out_dir}/cli_newmark_base_bad.csv)
# --nodes (decision 028): the long-format file of every leaf's nodes at every record (the half
# model mirrored: 3 leaves x 41 nodes x 6 records + the header), and a name of its own
stackbeam_cli_test(NAME cli_ok_nodes
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_nodes_run.csv
                        --nodes ${_cli_out_dir}/cli_nodes.csv
                   EXPECT_RC 0 EXPECT_TEXT "nodes" OUT ${_cli_out_dir}/cli_nodes.csv HEADER_PREFIX "t,leaf,x,w,theta"
                   MIN_LINES 739)
stackbeam_cli_test(NAME cli_bad_nodes_is_out
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_nodes_bad.csv
                        --nodes ${_cli_out_dir}/cli_nodes_bad.csv
                   EXPECT_RC 2 EXPECT_TEXT "--nodes: value" OUT ${_cli_out_dir}/cli_nodes_bad.csv)
# --stresses (issue 43 item 5): the long-format file of every leaf's stresses at every record
# (whole leaves: 3 leaves x 41 nodes x 6 records + the header), the summary's largest stress per
# leaf, the JSON's stresses section, and a name of its own
stackbeam_cli_test(NAME cli_ok_stresses
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_stresses_run.csv
                        --stresses ${_cli_out_dir}/cli_stresses.csv
                   EXPECT_RC 0 EXPECT_TEXT "stress leaf 0" OUT ${_cli_out_dir}/cli_stresses.csv
                   HEADER_PREFIX "t,leaf,x,sigma_top,sigma_bottom,axial_force,bending_moment,shear_force"
                   MIN_LINES 739)
# the JSON's samples: one per record (6 records: t = 0 .. 0.005 s every 0.001 s)
stackbeam_cli_test(NAME cli_ok_stresses_json
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_stresses_json.csv
                        --stresses ${_cli_out_dir}/cli_stresses_json_s.csv --summary ${_cli_out_dir}/cli_stresses.json
                   EXPECT_RC 0 JSON ${_cli_out_dir}/cli_stresses.json JSON_PATH "stresses|samples" JSON_RANGE "6|6")
stackbeam_cli_test(NAME cli_bad_stresses_is_out
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_stresses_bad.csv
                        --stresses ${_cli_out_dir}/cli_stresses_bad.csv
                   EXPECT_RC 2 EXPECT_TEXT "--stresses: value" OUT ${_cli_out_dir}/cli_stresses_bad.csv)
# the scenario's own key (outputs.stresses_path) asks for the same file, no option given; a clash
# with another output named by its key
stackbeam_cli_test(NAME cli_scenario_stresses_from_file
                   ARGS simulate --scenario ${CMAKE_CURRENT_SOURCE_DIR}/cli_stresses_scenario.toml --t-end 0.005 --quiet
                   EXPECT_RC 0 EXPECT_TEXT "stress leaf 0" OUT ${_cli_out_dir}/cli_stresses_scenario_stresses.csv
                   HEADER_PREFIX "t,leaf,x,sigma_top,sigma_bottom,axial_force,bending_moment,shear_force"
                   MIN_LINES 739)
stackbeam_cli_test(NAME cli_bad_scenario_stresses_is_nodes
                   ARGS simulate --scenario ${CMAKE_CURRENT_SOURCE_DIR}/cli_stresses_scenario.toml --t-end 0.005
                        --nodes cli_stresses_scenario_stresses.csv
                   EXPECT_RC 2 EXPECT_TEXT "outputs.stresses_path (file "
                   OUT ${_cli_out_dir}/cli_stresses_scenario_stresses.csv)
stackbeam_cli_test(NAME cli_ok_cvode_inertia_bonded
                   ARGS simulate --case bonded --mode cvode --beam-density 7850 --rtol 1e-6 --t-end 0.01
                        --out ${CMAKE_BINARY_DIR}/cli_cvode_inertia.csv
                   EXPECT_RC 0 EXPECT_TEXT "mode cvode" OUT ${CMAKE_BINARY_DIR}/cli_cvode_inertia.csv MIN_LINES 12)
stackbeam_cli_test(NAME cli_ok_cvode_inertia_friction
                   ARGS simulate --case friction --mode cvode --beam-density 7850 --rtol 1e-6 --t-end 0.01
                        --modal-cutoff 1000 --out ${CMAKE_BINARY_DIR}/cli_cvode_inertia_f.csv
                   EXPECT_RC 0 EXPECT_TEXT "4 modes up to 1000 rad/s" OUT ${CMAKE_BINARY_DIR}/cli_cvode_inertia_f.csv
                   MIN_LINES 12)
stackbeam_cli_test(NAME cli_ok_newmark_restitution
                   ARGS simulate --case friction --mode newmark --beam-density 7850 --restitution 0.5 --t-end 0.01
                        --dt 1e-4 --out ${CMAKE_BINARY_DIR}/cli_newmark_e.csv
                   EXPECT_RC 0 EXPECT_TEXT "mode newmark" OUT ${CMAKE_BINARY_DIR}/cli_newmark_e.csv MIN_LINES 12)
stackbeam_cli_test(NAME cli_bad_restitution_mode
                   ARGS simulate --case friction --restitution 0.5 --t-end 0.01 --out ${CMAKE_BINARY_DIR}/cli_e_bad.csv
                   EXPECT_RC 2 EXPECT_TEXT "only mode newmark with massive leaves has impacts" OUT ${CMAKE_BINARY_DIR}/cli_e_bad.csv)
stackbeam_cli_test(NAME cli_bad_modal_cutoff
                   ARGS simulate --case friction --mode cvode --beam-density 7850 --modal-cutoff -5 --t-end 0.01
                        --out ${CMAKE_BINARY_DIR}/cli_cvode_modal_bad.csv
                   EXPECT_RC 2 EXPECT_TEXT "--modal-cutoff: value '-5' is not allowed" OUT ${CMAKE_BINARY_DIR}/cli_cvode_modal_bad.csv)
# Scenario files: a good run (options given override the file), the file's output path
# (relative to the working directory, here the test's: build/tests), and the combinations
# that are rejected. The bad-input suite of scenario files is bad_input_tests.cmake.
set(_scenarios ${PROJECT_SOURCE_DIR}/scenarios)
stackbeam_cli_test(NAME cli_scenario_ok
                   ARGS simulate --scenario ${_scenarios}/paper_friction.toml --t-end 0.01 --out ${_cli_out_dir}/cli_scenario.csv
                   EXPECT_RC 0 EXPECT_TEXT "t_end 0.01 s" OUT ${_cli_out_dir}/cli_scenario.csv
                   HEADER_PREFIX "t,w,w_dot,force_on_mass,probe_friction_force" MIN_LINES 12)
stackbeam_cli_test(NAME cli_scenario_output_from_file
                   ARGS simulate --scenario ${_scenarios}/paper_frictionless.toml --t-end 0.01
                   EXPECT_RC 0 EXPECT_TEXT "output                     paper_frictionless.csv"
                   OUT ${_cli_out_dir}/paper_frictionless.csv MIN_LINES 12)
stackbeam_cli_test(NAME cli_scenario_parabolic_two_leaf  # profiles, eyes, a shackle (scenarios/README.md)
                   ARGS simulate --scenario ${_scenarios}/parabolic_two_leaf.toml --quiet --out ${_cli_out_dir}/cli_parabolic.csv
                   EXPECT_RC 0 OUT ${_cli_out_dir}/cli_parabolic.csv MIN_LINES 1001)
stackbeam_cli_test(NAME cli_scenario_with_case
                   ARGS simulate --scenario ${_scenarios}/paper_bonded.toml --case bonded --out ${_cli_out_dir}/cli_x_cli_scenario_with_case.csv
                   EXPECT_RC 2 EXPECT_TEXT "--case excludes --scenario" OUT ${_cli_out_dir}/cli_x_cli_scenario_with_case.csv)
stackbeam_cli_test(NAME cli_scenario_with_elements
                   ARGS simulate --scenario ${_scenarios}/paper_bonded.toml --elements 5 --out ${_cli_out_dir}/cli_x_cli_scenario_with_elements.csv
                   EXPECT_RC 2 EXPECT_TEXT "excludes --elements" OUT ${_cli_out_dir}/cli_x_cli_scenario_with_elements.csv)
stackbeam_cli_test(NAME cli_scenario_bad_override
                   ARGS simulate --scenario ${_scenarios}/paper_bonded.toml --dt nan --out ${_cli_out_dir}/cli_x_cli_scenario_bad_override.csv
                   EXPECT_RC 2 EXPECT_TEXT "--dt: value 'nan' is not allowed" OUT ${_cli_out_dir}/cli_x_cli_scenario_bad_override.csv)
# A file's value that an override makes invalid is named by its key and line, a flag's by the flag.
stackbeam_cli_test(NAME cli_scenario_value_by_key
                   ARGS simulate --scenario ${_scenarios}/rig_friction.toml --mode cvode --out ${_cli_out_dir}/cli_x_cli_scenario_value_by_key.csv
                   EXPECT_RC 2 EXPECT_TEXT "rig_friction.toml:71:8: loading.kind: value 'prescribed-displacement' is not available in mode cvode"
                   OUT ${_cli_out_dir}/cli_x_cli_scenario_value_by_key.csv)
stackbeam_cli_test(NAME cli_scenario_override_by_flag
                   ARGS simulate --scenario ${_scenarios}/paper_friction.toml --restitution 0.5 --out ${_cli_out_dir}/cli_x_cli_scenario_override_by_flag.csv
                   EXPECT_RC 2 EXPECT_TEXT "--restitution: value 0.5 is not used by mode closed-form"
                   OUT ${_cli_out_dir}/cli_x_cli_scenario_override_by_flag.csv)
stackbeam_cli_test(NAME cli_scenario_missing_file
                   ARGS simulate --scenario ${_cli_out_dir}/no_such_scenario.toml --out ${_cli_out_dir}/cli_x_cli_scenario_missing_file.csv
                   EXPECT_RC 2 EXPECT_TEXT "no_such_scenario.toml: the scenario file" OUT ${_cli_out_dir}/cli_x_cli_scenario_missing_file.csv)
stackbeam_cli_test(NAME cli_neither_case_nor_scenario
                   ARGS simulate --out ${_cli_out_dir}/cli_x_cli_neither_case_nor_scenario.csv
                   EXPECT_RC 2 EXPECT_TEXT "--case or --scenario: one of them is required" OUT ${_cli_out_dir}/cli_x_cli_neither_case_nor_scenario.csv)

# Loadings and outputs (issue 6): the rig test's loop figures in the summary and in the
# JSON file (loop area 5.33 J per cycle: tests/test_loadings.cpp proves it equals the
# friction work), the per-pair CSV (header + 21 pairs x 11 records), gravity from the
# command line, base excitation in mode cvode, and the figures.
stackbeam_cli_test(NAME cli_rig_summary
                   ARGS simulate --scenario ${_scenarios}/rig_friction.toml --t-end 2 --out ${_cli_out_dir}/cli_rig.csv
                        --summary ${_cli_out_dir}/cli_rig.json
                   EXPECT_RC 0 EXPECT_TEXT "t 1 to 2 s: area 5.33" OUT ${_cli_out_dir}/cli_rig.json HEADER_PREFIX "{"
                   JSON ${_cli_out_dir}/cli_rig.json JSON_PATH "hysteresis|loop_area_j" JSON_RANGE "5.33|5.34")
# Fancher's model fitted to the rig loop (docs/reduced-model.md): the summary line and the
# JSON's relative RMS error (0.47 %: tests/test_fancher.cpp proves the fit).
stackbeam_cli_test(NAME cli_rig_fancher
                   ARGS simulate --scenario ${_scenarios}/rig_friction.toml --t-end 2 --out ${_cli_out_dir}/cli_rigf.csv
                        --summary ${_cli_out_dir}/cli_rigf.json
                   EXPECT_RC 0 EXPECT_TEXT "fancher fit                upper 1195" OUT ${_cli_out_dir}/cli_rigf.json HEADER_PREFIX "{"
                   JSON ${_cli_out_dir}/cli_rigf.json JSON_PATH "fancher|rms_error_relative" JSON_RANGE "0.0047|0.0048")
# The windup figures (issue 44, decision 068): the windup rig of a flat leaf with the seat held
# (tests/sweep/windup_small.toml), its windup stiffness in the text summary and the JSON's "windup"
# section: 3 E I (1/a + 1/b) = 8828.57 N m/rad (tests/test_windup_figures.cpp proves it to 1e-9).
stackbeam_cli_test(NAME cli_windup_json
                   ARGS simulate --scenario ${PROJECT_SOURCE_DIR}/tests/sweep/windup_small.toml --out ${_cli_out_dir}/cli_windup.csv
                        --summary ${_cli_out_dir}/cli_windup.json
                   EXPECT_RC 0 EXPECT_TEXT "windup loop                t 1 to 2 s: stiffness 8828.57 N m/rad"
                   OUT ${_cli_out_dir}/cli_windup.json HEADER_PREFIX "{"
                   JSON ${_cli_out_dir}/cli_windup.json JSON_PATH "windup|stiffness_n_m_per_rad" JSON_RANGE "8828.57|8828.58")
# The windup map example (examples/sweep/windup_map.toml): every point runs, and each writes its last
# windup loop (the rig's last period: 1 s at dt 5 ms, 201 records and the header).
stackbeam_cli_test(NAME cli_windup_map
                   ARGS sweep ${PROJECT_SOURCE_DIR}/examples/sweep/windup_map.toml --out-dir ${_cli_out_dir}/cli_windup_map
                        --restart --no-plot --jobs 1
                   EXPECT_RC 0 EXPECT_TEXT "12 of 12 finished: 12 ok, 0 failed"
                   OUT ${_cli_out_dir}/cli_windup_map/loops/point-0011-windup.csv MIN_LINES 202
                   HEADER_PREFIX "t_s,seat_rotation_rad,seat_moment_n_m")
# A windup sweep's figures (tests/sweep/windup_loops.toml, decision 076): its loop family is the windup
# loops, seat moment against seat rotation (the seat held at w = 0 makes no vertical loop, so none drawn)
stackbeam_cli_test(NAME cli_windup_sweep_plot
                   ARGS sweep ${PROJECT_SOURCE_DIR}/tests/sweep/windup_loops.toml --out-dir ${_cli_out_dir}/cli_windup_sweep_plot
                        --restart --jobs 1
                   EXPECT_RC 0 EXPECT_TEXT "figures/windup_loops_along_loading_seat_rotation_rad_amplitude.png"
                   OUT ${_cli_out_dir}/cli_windup_sweep_plot/figures/windup_loops_along_loading_seat_rotation_rad_amplitude.png)
stackbeam_cli_test(NAME cli_pairs_csv
                   ARGS simulate --case friction --t-end 0.01 --out ${_cli_out_dir}/cli_p.csv --pairs ${_cli_out_dir}/cli_pairs.csv
                   EXPECT_RC 0 OUT ${_cli_out_dir}/cli_pairs.csv HEADER_PREFIX "t,pair,interface,x,state,p_n,p_t,gap,slip"
                   MIN_LINES 200)
stackbeam_cli_test(NAME cli_gravity
                   ARGS simulate --case bonded --gravity 9.81 --t-end 0.01 --out ${_cli_out_dir}/cli_g.csv
                        --summary ${_cli_out_dir}/cli_g.json
                   EXPECT_RC 0 EXPECT_TEXT "gravity 9.81" OUT ${_cli_out_dir}/cli_g.csv
                   JSON ${_cli_out_dir}/cli_g.json JSON_PATH "loading|gravity_m_per_s2" JSON_RANGE "9.81|9.81")
stackbeam_cli_test(NAME cli_bad_gravity
                   ARGS simulate --case bonded --gravity -1 --out ${_cli_out_dir}/cli_x_cli_bad_gravity.csv
                   EXPECT_RC 2 EXPECT_TEXT "--gravity: value '-1' is not allowed" OUT ${_cli_out_dir}/cli_x_cli_bad_gravity.csv)
stackbeam_cli_test(NAME cli_base_cvode
                   ARGS simulate --scenario ${_scenarios}/base_friction.toml --t-end 0.25 --quiet --out ${_cli_out_dir}/cli_base.csv
                        --summary ${_cli_out_dir}/cli_base.json --events ${_cli_out_dir}/cli_base_events.csv
                   EXPECT_RC 0 EXPECT_TEXT "loop                       t 0.125 to 0.25 s" OUT ${_cli_out_dir}/cli_base.csv
                   JSON ${_cli_out_dir}/cli_base.json JSON_PATH "cvode|steps" JSON_RANGE "1|1000000")
stackbeam_cli_test(NAME cli_plot
                   ARGS simulate --case friction --t-end 0.05 --quiet --out ${_cli_out_dir}/cli_plot.csv --plot ${_cli_out_dir}/cli_plot
                   EXPECT_RC 0 EXPECT_TEXT "cli_plot_loop.png" OUT ${_cli_out_dir}/cli_plot_loop.png)
# --plot on a single leaf without a probe pair (tests/cli_one_leaf.toml): the probe's friction force
# column is nan, so that figure is left out and the others (and the deformed stack after them) are drawn
stackbeam_cli_test(NAME cli_plot_one_leaf
                   ARGS simulate --scenario ${CMAKE_CURRENT_SOURCE_DIR}/cli_one_leaf.toml --quiet
                        --out ${_cli_out_dir}/cli_plot_one_leaf.csv --plot ${_cli_out_dir}/cli_plot_one_leaf
                   EXPECT_RC 0 EXPECT_TEXT "cli_plot_one_leaf_stack.png" OUT ${_cli_out_dir}/cli_plot_one_leaf_loop.png)
# --stack-color stress (issue 43 item 5): the deformed stack's leaves coloured by their stress; the
# data file has both figures' bands (3 leaves x 2 fibres x 41 nodes x 2 figures = 492 rows, the
# header and blank lines); a word other than state or stress, and the option without --plot, refused
stackbeam_cli_test(NAME cli_plot_stack_stress
                   ARGS simulate --case friction --t-end 0.02 --quiet --out ${_cli_out_dir}/cli_plot_stress.csv
                        --plot ${_cli_out_dir}/cli_plot_stress --stack-color stress
                   EXPECT_RC 0 EXPECT_TEXT "cli_plot_stress_stack.png" OUT ${_cli_out_dir}/cli_plot_stress_stack_stress.dat
                   HEADER_PREFIX "# x [mm], y [mm], sigma [MPa]" MIN_LINES 493)
stackbeam_cli_test(NAME cli_bad_stack_color_word
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_stack_color_bad.csv
                        --plot ${_cli_out_dir}/cli_stack_color_bad --stack-color pressure
                   EXPECT_RC 2 EXPECT_TEXT "--stack-color: value 'pressure' is not allowed: state or stress"
                   OUT ${_cli_out_dir}/cli_stack_color_bad.csv)
stackbeam_cli_test(NAME cli_bad_stack_color_without_plot
                   ARGS simulate --case friction --t-end 0.005 --out ${_cli_out_dir}/cli_stack_color_noplot.csv
                        --stack-color stress
                   EXPECT_RC 2 EXPECT_TEXT "--stack-color: value 'stress' colours the --plot figure"
                   OUT ${_cli_out_dir}/cli_stack_color_noplot.csv)

# The friction-mesh ratio kappa = mu (t_i + t_i+1) / (2 h) (model.hpp): in the summary
# (paper example: 0.5 x 5 mm / 12.5 mm = 0.2), and named in the note before the run and in
# the error of a step that fails on a mesh with kappa >= 1 (200 elements per half leaf:
# kappa = 2; the paper's iteration held to one iteration cannot settle the first step).
stackbeam_cli_test(NAME cli_friction_mesh_ratio_summary
                   ARGS simulate --case friction --t-end 0.005 --quiet --out ${_cli_out_dir}/cli_k.csv
                        --summary ${_cli_out_dir}/cli_k.json
                   EXPECT_RC 0 OUT ${_cli_out_dir}/cli_k.json HEADER_PREFIX "{"
                   JSON ${_cli_out_dir}/cli_k.json JSON_PATH "friction_mesh_ratio|kappa" JSON_RANGE "0.199999|0.200001")
stackbeam_cli_test(NAME cli_friction_mesh_ratio_failure
                   ARGS simulate --case friction --elements 200 --t-end 0.002 --solver paper --max-iterations 1
                        --out ${_cli_out_dir}/cli_k2.csv
                   EXPECT_RC 3 EXPECT_TEXT "the friction-mesh ratio mu (t_i + t_i+1) / (2 h) is 2 on interface 0"
                   OUT ${_cli_out_dir}/cli_k2.csv)

# The elastic interface (issue 18): --interface elastic on the paper case reports each
# interface's layer in the JSON summary (k_n = E / (1 - nu^2) / t = 2e10 / 0.91 / 0.005 =
# 4.3956e12 Pa/m, model.hpp interface_layer) and the ratio's decay length (l = 3.1203e-3 m,
# tests/test_friction_mesh_ratio.cpp); over a scenario file it overrides the file's contact
# law, and the note before the run warns of the elastic law at mu = 0.8 (>= 0.7).
stackbeam_cli_test(NAME cli_interface_elastic_summary
                   ARGS simulate --case friction --interface elastic --t-end 0.002 --quiet --out ${_cli_out_dir}/cli_el.csv
                        --summary ${_cli_out_dir}/cli_el.json
                   EXPECT_RC 0 EXPECT_TEXT "elastic: k_n 4.396e+12 Pa/m" OUT ${_cli_out_dir}/cli_el.csv
                   JSON ${_cli_out_dir}/cli_el.json JSON_PATH "interfaces|1|normal_stiffness_pa_per_m"
                   JSON_RANGE "4.3956e12|4.3957e12")
stackbeam_cli_test(NAME cli_interface_elastic_decay_length
                   ARGS simulate --case friction --interface elastic --t-end 0.002 --quiet --out ${_cli_out_dir}/cli_el2.csv
                        --summary ${_cli_out_dir}/cli_el2.json
                   EXPECT_RC 0 OUT ${_cli_out_dir}/cli_el2.csv
                   JSON ${_cli_out_dir}/cli_el2.json JSON_PATH "friction_mesh_ratio|decay_length_m"
                   JSON_RANGE "3.1202e-3|3.1203e-3")
stackbeam_cli_test(NAME cli_interface_over_scenario_warns
                   ARGS simulate --scenario ${CMAKE_CURRENT_LIST_DIR}/cli_elastic_high_mu.toml --interface elastic
                        --t-end 0.002 --quiet --out ${_cli_out_dir}/cli_el3.csv
                   EXPECT_RC 0 EXPECT_TEXT "note: interface 0 has the elastic law with mu = 0.8"
                   OUT ${_cli_out_dir}/cli_el3.csv)

# Close clamps merged (Model::adjustments(), decision 077): tests/cli_close_clamps.toml's clamps[0]
# and clamps[1], 0.4 mm apart on 12.5 mm elements, act as one clamp at their midpoint 0.1002 m; the
# text summary and the JSON summary's "model_adjustments" say so, naming them as written. The
# paper's friction case has no close clamps: neither the line nor the key.
stackbeam_cli_test(NAME cli_close_clamps_text
                   ARGS simulate --scenario ${CMAKE_CURRENT_LIST_DIR}/cli_close_clamps.toml
                        --out ${_cli_out_dir}/cli_close_clamps_text.csv
                   EXPECT_RC 0
                   EXPECT_TEXT "model adjustment           clamps[0] (x = 0.1 m) and clamps[1] (x = 0.1004 m), 0.0004 m apart, act as one clamp at x = 0.1002 m"
                   OUT ${_cli_out_dir}/cli_close_clamps_text.csv)
stackbeam_cli_test(NAME cli_close_clamps_summary
                   ARGS simulate --scenario ${CMAKE_CURRENT_LIST_DIR}/cli_close_clamps.toml
                        --out ${_cli_out_dir}/cli_close_clamps_summary.csv --summary ${_cli_out_dir}/cli_close_clamps_summary.json
                   EXPECT_RC 0 OUT ${_cli_out_dir}/cli_close_clamps_summary.json HEADER_PREFIX "{"
                   JSON ${_cli_out_dir}/cli_close_clamps_summary.json JSON_PATH "model_adjustments|0"
                   JSON_TEXT "clamps[0] (x = 0.1 m) and clamps[1] (x = 0.1004 m), 0.0004 m apart, act as one clamp at x = 0.1002 m")
stackbeam_cli_test(NAME cli_no_close_clamps_no_note
                   ARGS simulate --case friction --t-end 0.002
                        --out ${_cli_out_dir}/cli_no_close_clamps.csv --summary ${_cli_out_dir}/cli_no_close_clamps.json
                   EXPECT_RC 0 NOT_TEXT "model adjustment" OUT ${_cli_out_dir}/cli_no_close_clamps.json HEADER_PREFIX "{"
                   JSON ${_cli_out_dir}/cli_no_close_clamps.json JSON_ABSENT "model_adjustments")

# Interruption (apps/cli/run.hpp): SIGTERM / SIGINT once the first rows are on disk; exit
# status 143 / 130, the .partial files end on whole rows (every line the header's field
# count; the pairs at the CSV's last time), the summary says "interrupted": true.
find_program(_cli_bash bash)
if(_cli_bash)
  foreach(_sig_rc TERM:143 INT:130)
    string(REPLACE ":" ";" _sig_rc "${_sig_rc}")
    list(GET _sig_rc 0 _sig)
    list(GET _sig_rc 1 _rc)
    add_test(NAME cli_interrupt_sig${_sig}
             COMMAND ${_cli_bash} ${CMAKE_CURRENT_LIST_DIR}/cli_interrupt_test.sh $<TARGET_FILE:stackbeam_cli> ${_sig} ${_rc}
                     ${_cli_out_dir}/interrupt)
    set_tests_properties(cli_interrupt_sig${_sig} PROPERTIES LABELS cli TIMEOUT 180)
  endforeach()
endif()
