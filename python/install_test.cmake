# ctest python_install: installs the component `python` into PREFIX (emptied first) and runs
# a short case with the interpreter PYTHON importing the package from PREFIX/PACKAGE_DIR.
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --component python --prefix ${PREFIX}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install --component python failed (${rc})")
endif()
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PREFIX}/${PACKAGE_DIR}
          ${PYTHON} -c "import stackbeam, sys
assert stackbeam.__file__.startswith(sys.argv[1]), stackbeam.__file__
r = stackbeam.simulate(stackbeam.paper_example('bonded'), t_end_s=0.01)
assert len(r['w']) == 11
import stackbeam.plot" ${PREFIX}
  WORKING_DIRECTORY ${PREFIX}
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed package does not import from ${PREFIX}/${PACKAGE_DIR} (${rc})")
endif()
