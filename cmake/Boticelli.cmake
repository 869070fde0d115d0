# Build conventions shared by every module: warnings, sanitizers, subfolder discovery, tests.

# The warning set (documented in docs/architecture.md). -Werror via BOTICELLI_WERROR.
set(BOTICELLI_WARNINGS
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow
  -Wnon-virtual-dtor -Wold-style-cast -Woverloaded-virtual -Wnull-dereference
  -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)
if(BOTICELLI_WERROR)
  list(APPEND BOTICELLI_WARNINGS -Werror)
endif()
# Under the sanitizers GCC 12's -Wmaybe-uninitialized reports libstdc++'s own std::regex and
# std::function as uninitialized (GCC bug 105616: std::regex at -O1 with -fsanitize=address;
# GCC's manual says sanitizers make this warning unreliable). It needs optimisation: at -O0,
# where the asan preset was built before, it never ran at all; the sim and rpi4 presets keep it.
if(BOTICELLI_SANITIZE)
  list(APPEND BOTICELLI_WARNINGS -Wno-maybe-uninitialized)
endif()

if(BOTICELLI_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  # libstdc++'s own checks (std::array and std::vector indices, std::span, …): an index past
  # an array that is a member of an object stays inside the object, where AddressSanitizer
  # sees nothing.
  add_compile_definitions(_GLIBCXX_ASSERTIONS)
  add_link_options(-fsanitize=address,undefined)
endif()

# boticelli_target_defaults(TARGET): the project's warnings on one of its own targets.
function(boticelli_target_defaults target)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    return()
  endif()
  target_compile_options(${target} PRIVATE ${BOTICELLI_WARNINGS})
endfunction()

# boticelli_add_subdirectories([EXCLUDE dir...]): add every direct subfolder that has a
# CMakeLists.txt, so a new module (algo/<stage>, tests/<module>, ...) is picked up without
# editing its parent.
function(boticelli_add_subdirectories)
  cmake_parse_arguments(S "" "" "EXCLUDE" ${ARGN})
  file(GLOB children LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR}
       CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*)
  list(SORT children)
  foreach(child IN LISTS children)
    if(child IN_LIST S_EXCLUDE)
      continue()
    endif()
    if(IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${child}
       AND EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${child}/CMakeLists.txt)
      add_subdirectory(${child})
    endif()
  endforeach()
endfunction()

# boticelli_test_defaults(TARGET): the project's warnings, and line tables only (-g1) for
# test code: a test binary needs file:line in a backtrace, not full debug information,
# which took about a fifth of the tests' compile time.
function(boticelli_test_defaults target)
  boticelli_target_defaults(${target})
  if(CMAKE_BUILD_TYPE MATCHES "Deb")
    target_compile_options(${target} PRIVATE -g1)
  endif()
endfunction()

# boticelli_test_cost(TEST): ctest -j starts the tests of the highest COST first. A fresh
# clone has no timing history (Testing/Temporary/CTestCostData.txt), so without these the
# longest could start last and leave a core idle at the end: seconds of processor time
# measured in each kind of preset. Called where TEST is added (a directory's own tests).
function(boticelli_test_cost test)
  if(BOTICELLI_SANITIZE OR CMAKE_CROSSCOMPILING)
    set(costs test_sim_target_frames 130 test_floor_cue 75 test_mapping 40 test_sim 25 test_aln 20
        test_stereo 20 test_sdf 18 test_firmware 11)
  else()
    set(costs test_mission_MissionRooms 117 test_mission_MissionSeeds 100
        test_mission_MissionThesisRoom 86 test_mission_MissionResume 41 test_localization 26
        test_mission_MissionEstop 22 test_faults 15 test_sim 10)
  endif()
  list(FIND costs ${test} at)
  if(at GREATER_EQUAL 0)
    math(EXPR at "${at} + 1")
    list(GET costs ${at} cost)
    set_tests_properties(${test} PROPERTIES COST ${cost})
  endif()
endfunction()

# boticelli_add_test(NAME SOURCES src... [LIBS lib...] [ARGS arg...])
#   One CppUTest binary per module, registered with a plain add_test (CppUTest 4.0 has no
#   test discovery); ARGS are passed to it (e.g. -xn NAME to leave a test out in a preset).
#   Its main (tests/support/test_main.cpp) installs MockSupportPlugin; the allocation guard
#   is in boticelli_test_support. Under a cross preset ctest runs it through
#   CMAKE_CROSSCOMPILING_EMULATOR (qemu-aarch64).
function(boticelli_add_test name)
  cmake_parse_arguments(T "" "" "SOURCES;LIBS;ARGS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  boticelli_test_defaults(${name})
  target_link_libraries(${name} PRIVATE boticelli_test_support ${T_LIBS})
  add_test(NAME ${name} COMMAND ${name} ${T_ARGS})
  set_tests_properties(${name} PROPERTIES TIMEOUT 600)
  boticelli_test_cost(${name})
endfunction()
