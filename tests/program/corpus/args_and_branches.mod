MODULE ArgsAndBranches
    CONST robtarget pA := [[375, 0, 540], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pB := [[300, 150, 400], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST bool bDoubleGrip := FALSE;
    PERS num nMode := 2;
    PROC main()
        Visit pA, 40, v500;
        Visit pB, 20, v1000;
        IF bDoubleGrip THEN
            Visit pA, 10, v100;
        ELSE
            MoveJ pB, v1000, fine, tool0;
        ENDIF
        TEST nMode
        CASE 1:
            MoveJ pA, v200, fine, tool0;
        CASE 2, 3:
            MoveJ pA, v1000, fine, tool0;
        DEFAULT:
            Stop;
        ENDTEST
    ENDPROC
    PROC Visit(robtarget pT, num nUp, speeddata vApp)
        MoveJ Offs(pT, 0, 0, nUp), vApp, z10, tool0;
        MoveL pT, v200, fine, tool0;
        MoveL Offs(pT, 0, 0, nUp), v200, z10, tool0;
    ENDPROC
ENDMODULE
