# pscbranch_link_lapack(<target>): the LAPACK and BLAS pscbranch.h calls, and libm, as usage
# requirements of the INTERFACE target <target>. Shared by CMakeLists.txt (add_subdirectory,
# FetchContent) and the installed pscbranchConfig.cmake (find_package).
# FindLAPACK's imported targets when it finds them; else plain -llapack -lblas, which the
# linker resolves (Debian/Ubuntu's liblapack-dev libblas-dev, or OpenBLAS through the same names).
function(pscbranch_link_lapack target)
  if(NOT TARGET LAPACK::LAPACK)
    find_package(LAPACK QUIET)
  endif()
  if(TARGET LAPACK::LAPACK)
    target_link_libraries(${target} INTERFACE LAPACK::LAPACK)
    if(TARGET BLAS::BLAS)
      target_link_libraries(${target} INTERFACE BLAS::BLAS)
    endif()
  else()
    target_link_libraries(${target} INTERFACE lapack blas)
  endif()
  if(NOT WIN32)
    target_link_libraries(${target} INTERFACE m)
  endif()
endfunction()
