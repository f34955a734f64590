# PLUME_SANITIZE=ON: AddressSanitizer + UndefinedBehaviorSanitizer on every Plume target given to
# plume_sanitize() (the core library, the Python module, the C++ tests). Used by .ci/sanitize in
# its own build folder build-asan/. Any undefined behaviour stops the program
# (-fno-sanitize-recover), so a report is a failed test, never a line lost in the log.
# -O1 comes after the targets' own -O3 and so wins: ASan's reports stay exact at -O1 and the
# build is faster; -g1 (line tables only) gives the reports their file:line for less build time
# than -g. OpenVDB, TBB, OpenSubdiv and Python are Debian's uninstrumented libraries.
set(PLUME_SANITIZE_FLAGS
  -fsanitize=address,undefined
  -fno-sanitize-recover=undefined
  -fno-omit-frame-pointer
  -O1 -g1
)

function(plume_sanitize)
  foreach(target IN LISTS ARGN)
    target_compile_options(${target} PRIVATE ${PLUME_SANITIZE_FLAGS})
    # PUBLIC: whatever links the core (the fuzz replays, the seed maker) links the runtimes too.
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
  endforeach()
endfunction()
