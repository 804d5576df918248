# npm_ci.cmake - `npm ci` in viewer/ (DIR) with npm (NPM), unless node_modules already
# holds the lock file's packages: npm writes node_modules/.package-lock.json when it
# installs, so several build folders sharing viewer/ do not reinstall it under each other.
#   cmake -DDIR=viewer -DNPM=/usr/bin/npm -P viewer/npm_ci.cmake
if(EXISTS ${DIR}/node_modules/.package-lock.json AND
   NOT ${DIR}/package-lock.json IS_NEWER_THAN ${DIR}/node_modules/.package-lock.json)
  return()
endif()
execute_process(COMMAND ${NPM} ci --no-audit --no-fund --loglevel=error
                WORKING_DIRECTORY ${DIR} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "npm ci in ${DIR} failed (status ${status})")
endif()
