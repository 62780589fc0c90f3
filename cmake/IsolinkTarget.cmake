# isolink_target_defaults(TARGET): warnings (errors with ISOLINK_WERROR) and sanitizers.
function(isolink_target_defaults target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter)
  if(ISOLINK_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
