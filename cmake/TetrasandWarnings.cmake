# Strict warnings for our own targets only (third-party headers come in as SYSTEM).
function(tetrasand_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wcast-align -Wunused -Woverloaded-virtual)
  if(TETRASAND_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
