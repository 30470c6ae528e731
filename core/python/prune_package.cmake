# Removes from the assembled package (PACKAGE_DIR) every .py whose source (in SOURCE_DIR) is
# gone, so that a module moved or deleted in the checkout is not left importable in an
# incremental build: a stale aolab/compare.py beside aolab/study/compare.py would still be
# imported by whatever asked for it, and walked by the tests that import every module.
# _build_info.py is written by configure_file, not copied: it stays.
file(GLOB_RECURSE built RELATIVE ${PACKAGE_DIR} ${PACKAGE_DIR}/*.py)
foreach(file IN LISTS built)
  if(NOT file STREQUAL "_build_info.py" AND NOT EXISTS ${SOURCE_DIR}/${file})
    file(REMOVE ${PACKAGE_DIR}/${file})
  endif()
endforeach()
