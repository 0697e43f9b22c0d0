MODULE Touches
    ! touches of the reference tip, recorded with tool0 and wobj0
    CONST robtarget p10:=[[815.103,-161.836,560.115],[0.000000,1.000000,0.000000,0.000000],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget p20:=[[880.280,-133.007,575.374],[0.127679,0.943714,0.268536,-0.144878],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget p30:=[[814.777,0.673,496.825],[0.232210,0.890626,-0.364158,0.142313],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget p40:=[[948.359,-121.185,569.725],[0.122788,0.696364,0.664463,-0.241845],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget p50:=[[989.502,-317.762,473.475],[0.239371,-0.487764,-0.818599,-0.186237],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    CONST robtarget p60:=[[999.065,-133.594,553.420],[0.068361,0.641452,-0.711897,-0.277612],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];

    CONST jointtarget jHome:=[[0,-30,15,0,75,90],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
    PERS tooldata HeatGun:=[TRUE,[[0,0,180],[1,0,0,0]],[1.2,[0,0,60],[1,0,0,0],0,0,0]];

    PROC main()
        MoveAbsJ jHome, v500, fine, tool0;
        MoveJ p10, v100, fine, tool0\WObj:=wobj0;
        MoveL p20, v50, fine, tool0\WObj:=wobj0;
        MoveL p30,v100,fine,HeatGun\WObj:=wTable;
        MoveL \Conc, p40, v100\T:=2, z10, HeatGun;
        ! MoveL p50, v100, fine, tCommented;
        MoveJ p50, v100, fine, tool0\WObj:=wTable;
        MoveC p50, p60, v100, z5, tool0;
    ENDPROC
ENDMODULE
