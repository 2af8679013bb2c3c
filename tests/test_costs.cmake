# Read by ctest after the discovered tests are defined (TEST_INCLUDE_FILES, tests/CMakeLists.txt):
# the seconds a long CPU test takes under a sanitizer, as its COST, so that on a machine with no
# timings yet (a fresh clone) ctest starts it first rather than leaving it to run alone at the end
# (ThreadSanitizer's phase ran its slowest test, the 142nd, last: 47 of its 162 s). A name no test
# has (a filtered run) is passed over.
foreach(entry IN ITEMS "Contact.TheBoundsDoNotDependOnTheThreadCount=47"
                       "CpuThreads.TunedChunkingIsIdenticalOnALargerSheet=44"
                       "CpuFleet.EachSheetOfAMixedBatchMatchesItsRunAlone=41"
                       "Contact.ASheetForcedThroughItselfUntangles=30"
                       "Pieces.AHardPullLeavesNothingAboveThePins=29"
                       "Hand.ACrumpledBallKeepsItsSizeAndItsFolds=28")
  string(REPLACE "=" ";" entry "${entry}")
  list(GET entry 0 name)
  list(GET entry 1 seconds)
  set_tests_properties("${name}" PROPERTIES COST ${seconds})
endforeach()
