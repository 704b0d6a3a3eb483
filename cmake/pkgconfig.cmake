# pkg-config files for non-CMake builds (install component `library`):
#   stackbeam-contact.pc   -lstackbeam_contact (model, fe, contact), Requires eigen3
#   stackbeam.pc           -lstackbeam, Requires stackbeam-contact; Libs.private: the
#                          SUNDIALS libraries, for a static link (pkg-config --static)
# Included from the root CMakeLists.txt after the targets and SUNDIALS are known.

# The prefix relative to the .pc file's folder (${pcfiledir}), so that
# `cmake --install --prefix <other>` gives correct paths; absolute if the
# install directories are.
set(_pc_template ${CMAKE_CURRENT_LIST_DIR}/stackbeam.pc.in)
set(_pc_dir ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(PC_INCLUDEDIR "${CMAKE_INSTALL_FULL_INCLUDEDIR}")
  set(PC_LIBDIR "${CMAKE_INSTALL_FULL_LIBDIR}")
else()
  file(RELATIVE_PATH _pc_up "/${_pc_dir}" "/")
  string(REGEX REPLACE "/$" "" _pc_up "${_pc_up}")
  set(PC_PREFIX "\${pcfiledir}/${_pc_up}")
  set(PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
  set(PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()

# SUNDIALS' CVODE library as linker flags (-L<dir> -l<name>): its imported target's file.
get_target_property(_pc_cvode SUNDIALS::cvode_shared LOCATION)
get_filename_component(_pc_cvode_dir "${_pc_cvode}" DIRECTORY)
get_filename_component(_pc_cvode_name "${_pc_cvode}" NAME)
if(_pc_cvode_name MATCHES "^lib(.+)\\.so(\\.[0-9]+)*$")
  set(_pc_sundials_libs "-L${_pc_cvode_dir} -l${CMAKE_MATCH_1}")
else()
  set(_pc_sundials_libs "${_pc_cvode}")
endif()

# stackbeam_pc_file(<name> <library> <requires> <libs.private> <description>)
function(stackbeam_pc_file name library requires libs_private description)
  set(PC_NAME ${name})
  set(PC_LIBRARY ${library})
  set(PC_REQUIRES "${requires}")
  set(PC_LIBS_PRIVATE "${libs_private}")
  set(PC_DESCRIPTION "${description}")
  configure_file(${_pc_template} ${CMAKE_CURRENT_BINARY_DIR}/${name}.pc @ONLY)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/${name}.pc DESTINATION ${_pc_dir} COMPONENT library)
endfunction()

# CHOLMOD and KLU (when the build uses them): a static link needs them (pkg-config --static)
set(_pc_contact_private "")
if(CHOLMOD_FOUND)
  get_filename_component(_pc_cholmod_dir "${CHOLMOD_LIBRARY}" DIRECTORY)
  set(_pc_contact_private "-L${_pc_cholmod_dir} -lcholmod")
endif()
if(KLU_FOUND)  # the same (the fixed-pattern LU, decision 031)
  get_filename_component(_pc_klu_dir "${KLU_LIBRARY}" DIRECTORY)
  string(APPEND _pc_contact_private " -L${_pc_klu_dir} -lklu")
  string(STRIP "${_pc_contact_private}" _pc_contact_private)
endif()
stackbeam_pc_file(stackbeam-contact stackbeam_contact "eigen3 >= 3.3" "${_pc_contact_private}"
  "stackbeam's model, finite elements and contact solvers (no time integration, no SUNDIALS)")
stackbeam_pc_file(stackbeam stackbeam "stackbeam-contact = ${PROJECT_VERSION}" "${_pc_sundials_libs}"
  "${PROJECT_DESCRIPTION}")
