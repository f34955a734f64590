# PLUME_SANITIZE=ON: AddressSanitizer + UndefinedBehaviorSanitizer on every Plume target given to
# plume_sanitize() (the core library, the Python module, the C++ tests). Used by .ci/sanitize in
# its own build folder build-asan/. Any undefined behaviour stops the program
# (-fno-sanitize-recover), so a report is a failed test, never a line lost in the log.
# The optimisation level comes after the targets' own -O3 and so wins: -O1 for the code the
# tests spend their time in (the core), -O0 for the C++ tests' and the bindings' own files, which
# are heavy to compile (gtest, pybind11, OpenVDB headers) and light to run (-O0 compiled four
# heavy files in 65 s against 117 s at -O1). ASan's reports are exact at both; -g1 (line tables
# only) gives them their file:line for less build time than -g. OpenVDB, TBB, OpenSubdiv and
# Python are Debian's uninstrumented libraries.
set(PLUME_SANITIZE_FLAGS
  -fsanitize=address,undefined
  -fno-sanitize-recover=undefined
  -fno-omit-frame-pointer
  -g1
)

# plume_sanitize(OPTIMIZE <-O level> <target>...)
function(plume_sanitize)
  cmake_parse_arguments(ARG "" "OPTIMIZE" "" ${ARGN})
  foreach(target IN LISTS ARG_UNPARSED_ARGUMENTS)
    target_compile_options(${target} PRIVATE ${PLUME_SANITIZE_FLAGS} ${ARG_OPTIMIZE})
    # PUBLIC: whatever links the core (the fuzz replays, the seed maker) links the runtimes too.
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
  endforeach()
endfunction()
