MODULE MainModule
    ! Pick from the infeed, place on the fixture. A big part goes to the rear nest,
    ! a small one to the front nest: the sensor diBigPart decides, part by part.
    CONST robtarget pPick := [[0, 0, 0], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pVia := [[350, -130, 500], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pNest := [[0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num nApproach := 140;
    CONST num nRearShift := -40;
    VAR num nParts := 0;

    PROC main()
        MoveAbsJ jHome, v1000, fine, tGripper;
        WHILE TRUE DO
            Pick;
            MoveJ pVia, v1000, z50, tGripper;
            IF DInput(diBigPart) = 1 THEN
                Place Offs(pNest, nRearShift, 0, 0);
            ELSE
                Place pNest;
            ENDIF
            MoveAbsJ jHome, v1000, z50, tGripper;
            Incr nParts;
        ENDWHILE
    ENDPROC

    PROC Pick()
        MoveJ Offs(pPick, 0, 0, nApproach), v1000, z50, tGripper\WObj:=wInfeed;
        MoveL pPick, v300, fine, tGripper\WObj:=wInfeed;
        WaitDI diPartPresent, 1;
        SetDO doGripper, 1;
        WaitTime 0.3;
        GripLoad lPart;
        MoveL Offs(pPick, 0, 0, nApproach), v300, z20, tGripper\WObj:=wInfeed;
    ENDPROC

    PROC Place(robtarget pTarget)
        MoveJ Offs(pTarget, 0, 0, nApproach), v1000, z20, tGripper\WObj:=wFixture;
        MoveL pTarget, v200, fine, tGripper\WObj:=wFixture;
        SetDO doGripper, 0;
        WaitTime 0.3;
        GripLoad load0;
        MoveL Offs(pTarget, 0, 0, nApproach), v500, z20, tGripper\WObj:=wFixture;
    ENDPROC
ENDMODULE
