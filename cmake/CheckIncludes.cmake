# Fails when embedded code (hal/, firmware/) includes host-only code (measurement/, sim/,
# calibration/, diagnosis/, numerics/, tools/), when calibration/ includes the simulator or its
# file/ folder the fitting, when any library includes tests/ or tools/, or when a folder of
# diagnosis/ includes one above it. Run as: cmake -DROOT=<repo> -P CheckIncludes.cmake
file(GLOB_RECURSE embedded "${ROOT}/hal/*.hpp" "${ROOT}/hal/*.cpp" "${ROOT}/firmware/*.hpp" "${ROOT}/firmware/*.cpp")
file(GLOB_RECURSE host "${ROOT}/sim/*.hpp" "${ROOT}/sim/*.cpp" "${ROOT}/calibration/*.hpp"
     "${ROOT}/calibration/*.cpp" "${ROOT}/measurement/*.hpp" "${ROOT}/measurement/*.cpp"
     "${ROOT}/daemon/*.hpp" "${ROOT}/daemon/*.cpp" "${ROOT}/diagnosis/*.hpp" "${ROOT}/diagnosis/*.cpp")
set(bad "")
# forbid(FILES REGEX WHY): every file of FILES whose #include lines match REGEX is a violation.
function(forbid files regex why)
  foreach(f IN LISTS files)
    file(STRINGS "${f}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*${regex}")
    if(lines)
      list(APPEND bad "${f} (${why}): ${lines}")
    endif()
  endforeach()
  set(bad "${bad}" PARENT_SCOPE)
endfunction()

forbid("${embedded}" "[<\"](measurement|sim|calibration|diagnosis|numerics|daemon|tools|tests)/"
       "embedded code includes host code")
forbid("${embedded}" "<(Eigen|nlohmann|CLI|iostream|fstream|string|vector|map)"
       "embedded code uses a host header")
forbid("${host}" "[<\"](tools|tests)/" "a library includes a tool or a test")
# Calibration (fitting and files) stands below the simulator: it never includes it.
file(GLOB_RECURSE calibration "${ROOT}/calibration/*.hpp" "${ROOT}/calibration/*.cpp")
forbid("${calibration}" "[<\"](sim|diagnosis)/" "calibration includes the simulator")
# What a board loads (calibration/file) stands below the fitting (calibration/fit).
file(GLOB_RECURSE calibration_file "${ROOT}/calibration/file/*.hpp" "${ROOT}/calibration/file/*.cpp")
forbid("${calibration_file}" "[<\"]calibration/fit/" "the calibration file includes the fitting")
# The daemon's board part never includes the simulator; its simulated backend lives in daemon/sim.
file(GLOB daemon_board "${ROOT}/daemon/*.hpp" "${ROOT}/daemon/*.cpp")
forbid("${daemon_board}" "[<\"](sim|daemon/sim|calibration/fit|diagnosis)/"
       "the daemon's board part includes the simulator, the fitting or the diagnosis")
# The diagnosis (filters, engine, effect plug-ins, reports) knows recordings and numbers, not the
# simulator or a CLI; only evaluation/ uses the simulator.
file(GLOB_RECURSE diagnosis "${ROOT}/diagnosis/filters/*.[ch]pp" "${ROOT}/diagnosis/loader/*.[ch]pp"
     "${ROOT}/diagnosis/engine/*.[ch]pp"
     "${ROOT}/diagnosis/effects/*.[ch]pp" "${ROOT}/diagnosis/report/*.[ch]pp")
forbid("${diagnosis}" "[<\"](sim|calibration|daemon|tools|tests|CLI)/"
       "the diagnosis engine includes the simulator, a tool or a CLI")
# Inside diagnosis/ each folder uses only the ones below it: filters, loader < engine < effects <
# report.
file(GLOB_RECURSE diag_filters "${ROOT}/diagnosis/filters/*.[ch]pp")
forbid("${diag_filters}" "[<\"]diagnosis/(engine|effects|report|evaluation)/"
       "a diagnosis filter includes the engine")
file(GLOB_RECURSE diag_loader "${ROOT}/diagnosis/loader/*.[ch]pp")
forbid("${diag_loader}" "[<\"]diagnosis/(filters|engine|effects|report|evaluation)/"
       "the diagnosis loader includes the engine")
file(GLOB_RECURSE diag_engine "${ROOT}/diagnosis/engine/*.[ch]pp")
forbid("${diag_engine}" "[<\"]diagnosis/(effects|report|evaluation)/"
       "the diagnosis engine includes an effect plug-in or a report")
file(GLOB_RECURSE diag_effects "${ROOT}/diagnosis/effects/*.[ch]pp")
forbid("${diag_effects}" "[<\"]diagnosis/(report|evaluation)/" "an effect includes a report")

# The engine knows effects by their traits, never by name: no effect name of the vocabulary appears
# as a string in diagnosis/engine/.
file(STRINGS "${ROOT}/measurement/effect_vocabulary.hpp" vocabulary REGEX "^ *{\"[a-z_]+\", EffectKind::")
foreach(entry IN LISTS vocabulary)
  string(REGEX MATCH "\"[a-z_]+\"" effect_name "${entry}")
  if(effect_name STREQUAL "\"none\"")
    continue()
  endif()
  foreach(f IN LISTS diag_engine)
    file(STRINGS "${f}" hits REGEX "${effect_name}")
    if(hits)
      list(APPEND bad "${f} (the engine names the effect ${effect_name}): ${hits}")
    endif()
  endforeach()
endforeach()
if(NOT vocabulary)
  list(APPEND bad "measurement/effect_vocabulary.hpp: no effect names found for the engine check")
endif()

if(bad)
  list(JOIN bad "\n" msg)
  message(FATAL_ERROR "Architecture violation (see docs/architecture.md):\n${msg}")
endif()
message(STATUS "include rules hold for ${ROOT}")
