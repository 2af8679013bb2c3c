# Read by ctest after the discovered tests are defined (TEST_INCLUDE_FILES, tests/CMakeLists.txt):
# the seconds a long CPU test takes in ci or under a sanitizer, as its COST, so that on a machine
# with no timings yet (a fresh clone) ctest starts it first rather than leaving it to run alone at
# the end (ThreadSanitizer's phase ran its slowest test, the 142nd, last: 47 of its 162 s; later
# its 21 s SimdSimulation.TearingYank..., started 34th of 34). A name no test has (a filtered run)
# is passed over.
foreach(entry IN ITEMS "Contact.TheBoundsDoNotDependOnTheThreadCount=64"
                       "Stretch.TheHandDragsFoldsAndCrumplesPaperWithinThreePercent=44"
                       "Stretch.TheSettleSweepsHoldAFoldWithContactNearerTheLimitAndApart=17"
                       "CpuThreads.TunedChunkingIsIdenticalOnALargerSheet=43"
                       "CpuFleet.EachSheetOfAMixedBatchMatchesItsRunAlone=30"
                       "Hand.ACrumpledBallKeepsItsSizeAndItsFolds=34"
                       "Pieces.AHardPullLeavesNothingAboveThePins=27"
                       "CpuCandidateLists.ListsAreUsedAndChangeNothing=26"
                       "Contact.ASheetForcedThroughItselfUntangles=25"
                       "SimdSimulation.TearingYankIsIdenticalWithoutSimd=21"
                       "CpuThreads.FullAdjacencyAndFourThreadsAreIdentical=19"
                       "ContactLists.TheBoundsAndPushesAreThoseOfABruteForceSearch=17")
  string(REPLACE "=" ";" entry "${entry}")
  list(GET entry 0 name)
  list(GET entry 1 seconds)
  set_tests_properties("${name}" PROPERTIES COST ${seconds})
endforeach()
