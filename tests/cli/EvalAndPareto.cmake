# End-to-end checks of `transgi eval` and `transgi bench-pareto` on a tiny
# scene: exit codes, every promised output, the reference cache being reused,
# finite metrics for both methods, and the sweep's row count and Pareto front.
# Usage: cmake -DTRANSGI=... -DSCENE=... -DMODEL=... -DWORK=... -P EvalAndPareto.cmake
file(REMOVE_RECURSE ${WORK})
set(common --scene ${SCENE} --model ${MODEL} --width 24 --height 16 --spp 16 --cache ${WORK}/cache)

function(run_ok out_var)
  execute_process(COMMAND ${TRANSGI} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "transgi ${ARGN}\nexited with ${rc}:\n${out}${err}")
  endif()
  set(${out_var} "${out}${err}" PARENT_SCOPE)
endfunction()

# ---- eval -------------------------------------------------------------------
set(eval_args eval ${common} --out ${WORK}/eval --frames 6 --ddgi-frames 6 --ddgi-warmup 3 --probe-grid 2)
run_ok(first ${eval_args})
if(first MATCHES "from the cache")
  message(FATAL_ERROR "the first run cannot have a cached reference:\n${first}")
endif()
foreach(f index.html results.md results.json images/reference_gi.png images/reference_full.png images/reference_direct.exr
          images/transgi_gi.exr images/transgi_full.png images/ddgi_gi.exr images/ddgi_full.png
          heat/transgi_gi.png heat/ddgi_gi.png heat/transgi_full.png heat/ddgi_full.png)
  if(NOT EXISTS ${WORK}/eval/${f})
    message(FATAL_ERROR "eval did not write ${f}")
  endif()
endforeach()
file(READ ${WORK}/eval/results.json json)
foreach(method TransGI DDGI)
  string(JSON rmse GET "${json}" methods 0 gi rmse)
  if(method STREQUAL "DDGI")
    string(JSON rmse GET "${json}" methods 1 gi rmse)
  endif()
  if(NOT rmse MATCHES "^[0-9]+(\\.[0-9]+)?(e-?[0-9]+)?$")
    message(FATAL_ERROR "${method}: GI RMSE '${rmse}' is not a finite number")
  endif()
endforeach()
file(READ ${WORK}/eval/results.md md)
foreach(heading "GI only \\(Table 1\\)" "GI \\+ DI \\(Table 2" "Per-stage times" "Memory \\(Table 5\\)" "network inference" "probe update")
  if(NOT md MATCHES "${heading}")
    message(FATAL_ERROR "results.md lacks '${heading}':\n${md}")
  endif()
endforeach()
run_ok(second ${eval_args})
if(NOT second MATCHES "from the cache")
  message(FATAL_ERROR "the second run must reuse the cached reference:\n${second}")
endif()

# ---- bench-pareto -------------------------------------------------------------
run_ok(sweep bench-pareto ${common} --out ${WORK}/pareto --frames 4 --ddgi-frames 4 --timing-frames 2
       --grids 2,3 --rays 8,16 --maps 8,16 --widths 8,16 --depths 1,2 --latents 2,3 --ddgi-grids 2,3
       --default-grid 2 --default-rays 8 --default-map 8 --bake-iters 20 --bake-points 200 --bake-dirs 32)
foreach(f pareto.csv pareto.svg ablation.md)
  if(NOT EXISTS ${WORK}/pareto/${f})
    message(FATAL_ERROR "bench-pareto did not write ${f}")
  endif()
endforeach()
file(STRINGS ${WORK}/pareto/pareto.csv rows)
list(FILTER rows INCLUDE REGEX "^\"(TransGI|DDGI)\"")
list(LENGTH rows n)
# TransGI: default + grid 3 + rays 16 + map 16 + networks (16/1 default, width 8, depth 2, latent 2, latent 3) = 9; DDGI: 2.
if(NOT n EQUAL 11)
  message(FATAL_ERROR "expected 11 TransGI/DDGI rows in pareto.csv, got ${n}:\n${rows}")
endif()
file(STRINGS ${WORK}/pareto/pareto.csv front REGEX ",1,[0-9.]+$")
if(NOT front)
  message(FATAL_ERROR "no point is marked on the Pareto front")
endif()
