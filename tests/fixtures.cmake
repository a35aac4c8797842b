# Synthetic recordings shared by tests, made by the project's own generator once per test run.
# surroundd_fixture(name ARGS...) adds a setup test that writes ${SURROUNDD_FIXTURE_DIR}/<name>;
# tests that need it list FIXTURES <name>.
#
# SURROUNDD_FIXTURE_SYNTH: another build's surround-synth makes them instead of this build's, so a
# build of a few tests (the tsan preset's in scripts/test.sh) need not build the generator too.
set(SURROUNDD_FIXTURE_SYNTH "" CACHE FILEPATH
    "surround-synth that makes the test recordings (empty: this build's)")
function(surroundd_fixture name)
  set(synth surround-synth)
  if(SURROUNDD_FIXTURE_SYNTH)
    set(synth ${SURROUNDD_FIXTURE_SYNTH})
  endif()
  add_test(NAME fixture_${name}
           COMMAND ${synth} --out ${SURROUNDD_FIXTURE_DIR}/${name} --force ${ARGN})
  set_tests_properties(fixture_${name} PROPERTIES FIXTURES_SETUP ${name} LABELS fixtures)
endfunction()

set(paper ${PROJECT_SOURCE_DIR}/config/rigs/paper.yaml)
set(fisheye ${PROJECT_SOURCE_DIR}/config/rigs/fisheye.yaml)
set(paper_body ${PROJECT_SOURCE_DIR}/config/rigs/paper-body.yaml)
set(fisheye_body ${PROJECT_SOURCE_DIR}/config/rigs/fisheye-body.yaml)
set(small --size 320x180 --panorama-size 512x256)

surroundd_fixture(synth_small --rig ${paper} ${small} --seconds 1 --seed 7)
surroundd_fixture(synth_small_identity --rig ${paper} ${small} --seconds 1 --seed 7
                  --photometrics identity)
# Gains 0.7 / 1.3 and white balance shifted both ways, at the 720p benchmark's sizes: for the
# colour step across the seams.
surroundd_fixture(synth_seams --rig ${paper} --size 1280x720 --panorama-size 1536x768
                  --seconds 0.2 --seed 5 --photometrics extreme)
# One camera leaves out every third frame: for replay and synchronizer tests.
surroundd_fixture(synth_drop --rig ${paper} ${small} --seconds 2 --seed 11 --drop-every right:3)
surroundd_fixture(synth_fisheye --rig ${fisheye} ${small} --seconds 1 --seed 5)
# From 0.5 s on, 'left' freezes, 'right' goes black and 'back' stops: for camera health.
surroundd_fixture(synth_faults --rig ${paper} ${small} --seconds 1 --seed 13
                  --fault left:freeze@0.5 --fault right:black@0.5 --fault back:stop@0.5)
# The ego vehicle's body in view (and, for comparison, the same rig without it): 640x360 so that
# the masks' outlines are a small part of their area when masks are compared.
set(body --size 640x360 --panorama-size 256x128 --seconds 0.2 --photometrics identity)
surroundd_fixture(synth_body_paper --rig ${paper_body} ${body} --seed 3)
surroundd_fixture(synth_body_paper_plain --rig ${paper_body} ${body} --seed 3 --no-body)
surroundd_fixture(synth_body_fisheye --rig ${fisheye_body} ${body} --seed 3 --scene near-objects)
# A drive with the body in view, as a user records one for surround-calibrate mask --from: four
# ten seconds at two pictures a second (15 m, turning 23 degrees), the photometrics random (noise,
# exposure drift).
set(drive --size 640x360 --panorama-size 256x128 --seconds 10 --fps 2)
surroundd_fixture(synth_drive_paper --rig ${paper_body} ${drive} --seed 3)
surroundd_fixture(synth_drive_fisheye --rig ${fisheye_body} ${drive} --seed 3 --scene near-objects)
# The same drive at 1280x720, where a picture's pixel spans about a centimetre of the overlaps'
# ground: for the mounts corrected from the road.
# The fisheye rig's back camera knocked, 3 degrees of pitch from 2 s on (surround-synth --turn).
surroundd_fixture(synth_turn --rig ${fisheye_body} --size 1280x720 --panorama-size 256x128
                  --seconds 4 --fps 1 --seed 3 --photometrics identity --turn back:0,3,0@2)
surroundd_fixture(synth_drive_fisheye_hd --rig ${fisheye_body} --size 1280x720 --panorama-size 256x128
                  --seconds 10 --fps 2 --seed 3 --scene near-objects)
