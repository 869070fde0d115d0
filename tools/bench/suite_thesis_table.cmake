# Suite thesis-table: regression fusion (ALN) vs the evidence grid on the §4.8.2 rooms.
target_sources(boticelli-bench PRIVATE ${CMAKE_CURRENT_LIST_DIR}/synthetic_rooms.cpp)
target_link_libraries(boticelli-bench PRIVATE boticelli_evidence boticelli_fusion boticelli_aln)
