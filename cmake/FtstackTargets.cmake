# Target helpers: warning flags, embedded flags and the layer rules that keep the architecture honest.
#
# Layers (by target name) and what each may link (ftstack_check_layers below enforces it; CMake
# configuration fails on a violation, and tests/CMakeLists.txt proves it with injected ones):
#   ftstack_hal          the HAL interface (header-only)              -> nothing of ours
#   ftstack_hal_*        HAL backends (sim ADC, HX711, SPI ADC, GPIO) -> hal_if
#   ftstack_fw_*         firmware: integer core, device, Modbus       -> hal_if, fw
#   ftstack_measurement  host types: wrench, units, recording format, -> nothing of ours
#                        effect vocabulary, shared numerics
#   ftstack_cal_file     what a board loads: calibration file, slots, -> hal_if, fw, meas
#                        the unit a calibration reads
#   ftstack_cal_fit      fitting, fit reports, offline apply          -> hal_if, fw, meas, calfile, calfit
#   ftstack_cal_ati        (calfit) the ATI calibration-file import; ftstack_cal_fit links it
#   ftstack_sim*         physics simulator, rigs, recordings          -> hal_if, hal, meas, calfile, sim
#   ftstack_daemon       ftd's daemon (board and host)                -> hal_if, hal, fw, meas, calfile, daemon
#   ftstack_rdt            (daemon) its RDT server; ftstack_daemon links it
#   ftstack_daemon_sim   ftd's simulated backend (host only)          -> the daemon's + sim, daemon
#   ftstack_diagnosis_filters  the diagnosis's closed-form filters    -> nothing of ours
#   ftstack_diagnosis_loader  recordings into the diagnosis's DiagData -> meas
#   ftstack_diagnosis    sim-vs-real diagnosis engine and effects     -> meas, diag_filters, diag_loader
#   ftstack_diagnosis_report  its HTML/JSON reports                   -> meas, diag
#   ftstack_diagnosis_eval    scorecard, demo, model prediction       -> diag, sim (and below)
# Every ftstack_* library has one of these layers (a library without one fails configuration).
# The programs of tools/ are argument parsing only: each is declared with ftstack_program and
# may link the layers it names, nothing else (ftd: the daemon, and its simulator on a host; ftcal:
# calibration and the rig simulation; ftsim: the simulator; ftdiag: the diagnosis).
# Tests, benchmarks and fuzzers may link any library; nothing links a test.

add_library(ftstack_warnings INTERFACE)
target_compile_options(ftstack_warnings INTERFACE -Wall -Wextra -Wshadow -Wnon-virtual-dtor)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  # GCC 12 reports false -Wrestrict positives inside std::string at -O2/-O3 (GCC PR 105329).
  target_compile_options(ftstack_warnings INTERFACE -Wno-restrict)
endif()
if(FTSTACK_WERROR)
  target_compile_options(ftstack_warnings INTERFACE -Werror)
endif()
if(FTSTACK_FUZZ)
  # Coverage for libFuzzer everywhere, ASan+UBSan (fail on the first finding); exceptions stay on
  # for host code, embedded code keeps -fno-exceptions.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize=vptr
                      -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -g1)
  add_link_options(-fsanitize=address,undefined)
endif()
# Sanitizer builds carry line tables only (-g1, after the build type's -g): reports keep file and
# line, and the builds take about a third less time than with full debug information.
if(FTSTACK_SANITIZE)
  # vptr checks need RTTI, which embedded code (-fno-rtti) does not have.
  add_compile_options(-fsanitize=address,undefined -fno-sanitize=vptr -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -g1)
  add_link_options(-fsanitize=address,undefined)
  # GCC's flow analysis reports spurious "may be used uninitialized" through the instrumented code
  # (the GCC manual warns of this for -fsanitize); the Release build keeps the warning as an error.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    add_compile_options(-Wno-maybe-uninitialized)
  endif()
endif()

if(FTSTACK_TSAN)
  if(FTSTACK_SANITIZE OR FTSTACK_FUZZ)
    message(FATAL_ERROR "FTSTACK_TSAN cannot be combined with ASan (FTSTACK_SANITIZE, FTSTACK_FUZZ)")
  endif()
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer -g1)
  add_link_options(-fsanitize=thread)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    # TSan does not model std::atomic_thread_fence (firmware/seqlock.hpp); GCC says so with -Wtsan.
    # The seqlock's payload is relaxed atomics, so TSan still sees no plain data race there; the
    # fences' ordering is what TSan cannot check (the seqlock's own tests do).
    add_compile_options(-Wno-tsan)
  endif()
endif()

# Embedded code (hal/, firmware/): no exceptions, no RTTI.
add_library(ftstack_embedded INTERFACE)
target_compile_options(ftstack_embedded INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-fno-exceptions -fno-rtti>)
target_link_libraries(ftstack_embedded INTERFACE ftstack_warnings)

set_property(GLOBAL PROPERTY FTSTACK_LIBRARIES "")

# ftstack_library(NAME [STATIC|INTERFACE] [EMBEDDED] SOURCES ...)
function(ftstack_library name)
  cmake_parse_arguments(ARG "INTERFACE;EMBEDDED" "" "SOURCES" ${ARGN})
  if(ARG_INTERFACE)
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${PROJECT_SOURCE_DIR})
  else()
    add_library(${name} STATIC ${ARG_SOURCES})
    target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
    if(ARG_EMBEDDED)
      target_link_libraries(${name} PRIVATE ftstack_embedded)
    else()
      target_link_libraries(${name} PRIVATE ftstack_warnings)
    endif()
  endif()
  set_property(GLOBAL APPEND PROPERTY FTSTACK_LIBRARIES ${name})
endfunction()

# ftstack_program(NAME LAYERS layer...): a program of tools/ and the layers it may link directly.
function(ftstack_program name)
  cmake_parse_arguments(ARG "" "" "LAYERS" ${ARGN})
  set_property(TARGET ${name} PROPERTY FTSTACK_LAYERS "${ARG_LAYERS}")
  set_property(GLOBAL APPEND PROPERTY FTSTACK_PROGRAMS ${name})
endfunction()

function(_ftstack_layer_of target out)
  if(target STREQUAL "ftstack_hal")
    set(${out} "hal_if" PARENT_SCOPE)
  elseif(target MATCHES "^ftstack_hal_")
    set(${out} "hal" PARENT_SCOPE)
  elseif(target MATCHES "^ftstack_fw_")
    set(${out} "fw" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_measurement")
    set(${out} "meas" PARENT_SCOPE)
  elseif(target MATCHES "^ftstack_sim")
    set(${out} "sim" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_cal_file")
    set(${out} "calfile" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_cal_fit" OR target STREQUAL "ftstack_cal_ati")
    set(${out} "calfit" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_daemon" OR target STREQUAL "ftstack_rdt")
    set(${out} "daemon" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_daemon_sim")
    set(${out} "daemon_sim" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_diagnosis_filters")
    set(${out} "diag_filters" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_diagnosis_loader")
    set(${out} "diag_loader" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_diagnosis")
    set(${out} "diag" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_diagnosis_report")
    set(${out} "diag_report" PARENT_SCOPE)
  elseif(target STREQUAL "ftstack_diagnosis_eval")
    set(${out} "diag_eval" PARENT_SCOPE)
  elseif(target MATCHES "^ftstack_test|^test_")
    set(${out} "test" PARENT_SCOPE)
  else()
    set(${out} "external" PARENT_SCOPE)
  endif()
endfunction()

function(ftstack_check_layers)
  set(allowed_hal_if "")
  set(allowed_hal "hal_if")
  set(allowed_fw "hal_if;fw")
  set(allowed_meas "")
  set(allowed_calfile "hal_if;fw;meas")
  set(allowed_calfit "hal_if;fw;meas;calfile;calfit")
  set(allowed_sim "hal_if;hal;meas;calfile;sim")
  set(allowed_daemon "hal_if;hal;fw;meas;calfile;daemon")
  set(allowed_daemon_sim "hal_if;hal;fw;meas;calfile;sim;daemon")
  set(allowed_diag_filters "")
  set(allowed_diag_loader "meas")
  set(allowed_diag "meas;diag_filters;diag_loader")
  set(allowed_diag_report "meas;diag_filters;diag_loader;diag")
  set(allowed_diag_eval "hal_if;hal;meas;calfile;sim;diag_filters;diag_loader;diag")
  get_property(libs GLOBAL PROPERTY FTSTACK_LIBRARIES)
  get_property(programs GLOBAL PROPERTY FTSTACK_PROGRAMS)
  foreach(lib IN LISTS libs programs)
    if(lib IN_LIST programs)
      set(layer "program")
      get_target_property(allowed_program ${lib} FTSTACK_LAYERS)
    else()
      _ftstack_layer_of(${lib} layer)
      if(layer STREQUAL "external" OR layer STREQUAL "test")
        message(FATAL_ERROR "Architecture violation: library ${lib} has no layer (name it for one "
                            "in cmake/FtstackTargets.cmake). See docs/architecture.md.")
      endif()
    endif()
    get_target_property(type ${lib} TYPE)
    if(type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(deps ${lib} INTERFACE_LINK_LIBRARIES)
    else()
      get_target_property(deps ${lib} LINK_LIBRARIES)
    endif()
    if(NOT deps)
      continue()
    endif()
    foreach(dep IN LISTS deps)
      string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" dep "${dep}")
      if(NOT dep MATCHES "^ftstack_" OR dep STREQUAL "ftstack_warnings" OR dep STREQUAL "ftstack_embedded")
        continue()
      endif()
      _ftstack_layer_of(${dep} dep_layer)
      if(NOT dep_layer IN_LIST allowed_${layer})
        message(FATAL_ERROR "Architecture violation: ${lib} (layer ${layer}) links ${dep} "
                            "(layer ${dep_layer}). See docs/architecture.md.")
      endif()
    endforeach()
  endforeach()
endfunction()
