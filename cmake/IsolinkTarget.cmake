# isolink_target_defaults(TARGET): warnings (errors with ISOLINK_WERROR) and sanitizers.
function(isolink_target_defaults target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter
                         -Wno-missing-field-initializers)  # designated initializers omit fields
  # GCC 12 reports false -Wrestrict positives inside std::string at -O2 (GCC PR 105329).
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(ISOLINK_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()
