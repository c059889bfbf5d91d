# FCLib and the HDF5 libraries its files are checked with (tools/fclib), found by
# hand: FCLib's config file looks for HDF5 with C compiler checks, which fail in a
# C++-only project. Included by bench/siconos.cmake (nscd_fclib) and fuzz/ (the
# fclib_reader target). Sets NSCD_FCLIB_FOUND, NSCD_FCLIB_INCLUDE_DIRS,
# NSCD_FCLIB_LIBRARIES and NSCD_FCLIB_READER_SOURCES (the reader both build).
find_path(NSCD_FCLIB_INCLUDE_DIR fclib.h)
find_library(NSCD_FCLIB_LIBRARY fclib)
find_path(NSCD_HDF5_INCLUDE_DIR hdf5_hl.h PATH_SUFFIXES hdf5/serial)
find_library(NSCD_HDF5_LIBRARY NAMES hdf5_serial hdf5)
find_library(NSCD_HDF5_HL_LIBRARY NAMES hdf5_serial_hl hdf5_hl)
if(NSCD_FCLIB_INCLUDE_DIR AND NSCD_FCLIB_LIBRARY AND NSCD_HDF5_INCLUDE_DIR AND NSCD_HDF5_LIBRARY AND
   NSCD_HDF5_HL_LIBRARY)
  set(NSCD_FCLIB_FOUND TRUE)
else()
  set(NSCD_FCLIB_FOUND FALSE)
endif()
set(NSCD_FCLIB_INCLUDE_DIRS ${NSCD_FCLIB_INCLUDE_DIR} ${NSCD_HDF5_INCLUDE_DIR})
set(NSCD_FCLIB_LIBRARIES ${NSCD_FCLIB_LIBRARY} ${NSCD_HDF5_HL_LIBRARY} ${NSCD_HDF5_LIBRARY})
set(NSCD_FCLIB_READER_SOURCES ${CMAKE_CURRENT_LIST_DIR}/read_fclib_problem.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fclib_file_check.cpp)
