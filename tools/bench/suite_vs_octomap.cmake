# Suite vs-octomap: navigation polygons from the ALN occupancy model vs from an OctoMap octree.
# OctoMap (Debian liboctomap-dev) is optional: without it only our side is measured.
get_target_property(_vs_octomap_sources boticelli-bench SOURCES)
if(NOT "${_vs_octomap_sources}" MATCHES "synthetic_rooms.cpp")
  target_sources(boticelli-bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/synthetic_rooms.cpp)
endif()
target_link_libraries(boticelli-bench PRIVATE boticelli_mapping boticelli_evidence boticelli_aln)
find_package(octomap QUIET)
if(octomap_FOUND)
  target_include_directories(boticelli-bench SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
  target_link_libraries(boticelli-bench PRIVATE ${OCTOMAP_LIBRARIES})
  target_compile_definitions(boticelli-bench PRIVATE BOTICELLI_HAVE_OCTOMAP=1)
endif()
