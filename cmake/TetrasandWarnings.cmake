# Strict warnings for our own targets only (third-party headers come in as SYSTEM).
function(tetrasand_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wcast-align -Wunused -Woverloaded-virtual)
  if(TETRASAND_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  # GCC 12 under -fsanitize=address at -O1 reports -Wmaybe-uninitialized inside libstdc++'s own
  # std::regex and std::function (GCC bug 105562 and kin); the Release build keeps the warning.
  target_compile_options(${target} PRIVATE $<$<CONFIG:Sanitize>:-Wno-maybe-uninitialized>)
endfunction()
