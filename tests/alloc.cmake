# The allocation-counting test sees every heap call of the objects it links.
target_link_options(test_alloc PRIVATE
  -Wl,--wrap=malloc -Wl,--wrap=calloc -Wl,--wrap=realloc -Wl,--wrap=free)
