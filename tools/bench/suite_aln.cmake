# The aln benchmark suite needs the ALN library.
target_link_libraries(boticelli-bench PRIVATE boticelli_aln)
