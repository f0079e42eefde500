# Fails when embedded code (hal/, firmware/) includes host-only code (measurement/, sim/,
# calibration/, diagnosis/, numerics/, tools/), when calibration/ includes the simulator, or when any
# library includes tests/ or tools/. Run as: cmake -DROOT=<repo> -P CheckIncludes.cmake
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
# The diagnosis engine and its reports know recordings and numbers, not the simulator or a CLI.
file(GLOB engine "${ROOT}/diagnosis/*.hpp" "${ROOT}/diagnosis/*.cpp" "${ROOT}/diagnosis/report/*.hpp"
     "${ROOT}/diagnosis/report/*.cpp")
forbid("${engine}" "[<\"](sim|calibration|daemon|tools|tests|CLI)/"
       "the diagnosis engine includes the simulator, a tool or a CLI")

if(bad)
  list(JOIN bad "\n" msg)
  message(FATAL_ERROR "Architecture violation (see docs/architecture.md):\n${msg}")
endif()
message(STATUS "include rules hold for ${ROOT}")
