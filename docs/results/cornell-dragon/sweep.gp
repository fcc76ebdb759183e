# Redraw with: cd docs/results/cornell-dragon && gnuplot sweep.gp
set terminal pngcairo size 1000,700 font 'sans,10'
set logscale x
set grid
set key top right
set ylabel 'indirect irradiance: relative RMSE vs reference, 4x4 bins (%)'
set output 'error-vs-bake-time.png'
set title 'cornell-dragon: error against bake time, s'
set xlabel 'bake time, s (log scale)'
plot 'plot-data/all-time.dat' using 1:2 with points pt 7 ps 1 lc rgb '#909090' title 'settings', \
     'plot-data/front-time.dat' using 1:2 with linespoints pt 7 ps 1.2 lw 2 lc rgb '#d62728' title 'Pareto front', \
     'plot-data/front-time.dat' using 1:2:3 with labels offset 1,0.6 left font 'sans,8' notitle, \
     'plot-data/paper-time.dat' using 1:2 with points pt 5 ps 2.2 lc rgb '#1f77b4' title 'paper (d6 600k k300 v4)'
set output 'error-vs-memory.png'
set title 'cornell-dragon: error against GPU octree + VDL textures, KiB'
set xlabel 'GPU octree + VDL textures, KiB (log scale)'
plot 'plot-data/all-memory.dat' using 1:2 with points pt 7 ps 1 lc rgb '#909090' title 'settings', \
     'plot-data/front-memory.dat' using 1:2 with linespoints pt 7 ps 1.2 lw 2 lc rgb '#d62728' title 'Pareto front', \
     'plot-data/front-memory.dat' using 1:2:3 with labels offset 1,0.6 left font 'sans,8' notitle, \
     'plot-data/tolerance-memory.dat' using 1:2 with linespoints pt 9 ps 1.2 lw 2 lc rgb '#2ca02c' title 'adaptive leaves (tolerance)', \
     'plot-data/tolerance-memory.dat' using 1:2:3 with labels offset -1,-0.9 right font 'sans,8' tc rgb '#2ca02c' notitle, \
     'plot-data/paper-memory.dat' using 1:2 with points pt 5 ps 2.2 lc rgb '#1f77b4' title 'paper (d6 600k k300 v4)'
