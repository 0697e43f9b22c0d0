MODULE CalibTools
    ! tools as RobotStudio writes them: 6 significant digits, a quaternion near unit length
    PERS tooldata tGripper:=[TRUE,[[0,1,330],[1,0,0,0]],[3,[0,0,30],[1,0,0,0],0,0,0]];
    TASK PERS tooldata tAngled:=[TRUE,[[0,6.4,170],[0.99998,0.00625,0,0]],[25,[0,0,80],[1,0,0,0],0,0,0]];
    PERS wobjdata wTable:=[FALSE,TRUE,"",[[0,0,0],[1,0,0,0]],[[992.91,-216.96,565],[0,0,1,0]]];
ENDMODULE
